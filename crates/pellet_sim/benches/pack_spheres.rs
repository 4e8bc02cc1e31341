//! Packing benchmark: 100 and 300 spheres of 10 mm poured into a tube (plain std::time).
//!
//! Run with `cargo bench --profile dev --bench pack_spheres` (or `cargo bench`). The simulated
//! time per case is `PELLET_BENCH_SIM_SECONDS` (default 1.0 s); a case also stops once its wall
//! time exceeds `PELLET_BENCH_WALL_SECONDS` (default 300 s), and the table says how far it got.
//! `PELLET_BENCH_SIZES=100,300` chooses the pellet counts; `PELLET_BENCH_EXACT_ROWS` the largest
//! island solved by Baraff's method (default 64, as in physics.md §8.1);
//! `PELLET_BENCH_SOLVER=pgs` the iterative solver (default APGD).

use pellet_sim::{
    BodyType, Container, EngineParams, IterativeSolver, Material, Pipeline, Quat, Vec3, WallMaterial, World,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

struct Row {
    n: usize,
    wall_s: f64,
    sim_s: f64,
    substeps: u64,
    contacts_per_substep: f64,
    iterations_per_substep: f64,
    worst_residual: f64,
    unconverged: u32,
    max_pen_rel: f64,
    ke_final: f64,
}

fn env(name: &str, default: f64) -> f64 {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

fn case(n: usize, sim_seconds: f64, wall_limit: f64) -> Row {
    let r = 0.005;
    let tube_d = 0.06;
    let mut world = World::new(
        Container::tube(tube_d).expect("tube"),
        Material { density: 2000.0, cor: 0.5, friction: 0.3 },
        WallMaterial { cor: 0.5, friction: 0.3 },
        EngineParams {
            exact_solver_max_rows: env("PELLET_BENCH_EXACT_ROWS", 64.0) as usize,
            iterative_solver: match std::env::var("PELLET_BENCH_SOLVER").as_deref() {
                Ok("pgs") => IterativeSolver::Pgs,
                _ => IterativeSolver::Apgd,
            },
            ..EngineParams::default()
        },
    )
    .expect("world");
    let t = world.register_type(BodyType::solid_sphere(r).expect("type")).expect("register");
    // Loose random column above the floor, non-overlapping.
    let mut rng = ChaCha8Rng::seed_from_u64(2026);
    let rt = 0.5 * tube_d - 1.05 * r;
    let mut placed: Vec<Vec3> = Vec::new();
    let mut z_top = 0.02;
    while placed.len() < n {
        let x = Vec3::new(rng.random_range(-rt..rt), rng.random_range(-rt..rt), rng.random_range(1.5 * r..z_top));
        z_top += 0.0004;
        if x.xy().norm() > rt || placed.iter().any(|p| (p - x).norm() < 2.05 * r) {
            continue;
        }
        world.add_body(t, x, Quat::identity(), Vec3::zeros(), Vec3::zeros()).expect("add");
        placed.push(x);
    }
    let mut pipeline = Pipeline::new();
    let start = Instant::now();
    let (mut substeps, mut contacts, mut iterations, mut unconverged) = (0u64, 0u64, 0u64, 0u32);
    let (mut residual, mut pen): (f64, f64) = (0.0, 0.0);
    while world.time() < sim_seconds && start.elapsed().as_secs_f64() < wall_limit {
        let rep = world.step(1.0 / 40.0, &mut pipeline).expect("step");
        substeps += rep.substeps as u64;
        contacts += rep.contacts;
        iterations += rep.solver_iterations;
        unconverged += rep.unconverged_islands;
        residual = residual.max(rep.solver_residual);
        pen = pen.max(rep.max_penetration);
    }
    let s = substeps.max(1) as f64;
    Row {
        n,
        wall_s: start.elapsed().as_secs_f64(),
        sim_s: world.time(),
        substeps,
        contacts_per_substep: contacts as f64 / s,
        iterations_per_substep: iterations as f64 / s,
        worst_residual: residual,
        unconverged,
        max_pen_rel: pen / (2.0 * r),
        ke_final: world.kinetic_energy(),
    }
}

fn main() {
    let sim = env("PELLET_BENCH_SIM_SECONDS", 1.0);
    let wall = env("PELLET_BENCH_WALL_SECONDS", 300.0);
    println!(
        "{:>5} {:>9} {:>8} {:>9} {:>10} {:>11} {:>10} {:>7} {:>9} {:>10}",
        "N", "wall[s]", "sim[s]", "substeps", "contacts/", "solver it/", "worst res", "unconv", "pen/d", "KE end[J]"
    );
    println!(
        "{:>5} {:>9} {:>8} {:>9} {:>10} {:>11} {:>10} {:>7} {:>9} {:>10}",
        "", "", "", "", "substep", "substep", "[m/s2]", "islands", "", ""
    );
    let sizes: Vec<usize> = std::env::var("PELLET_BENCH_SIZES")
        .ok()
        .map(|v| v.split(',').filter_map(|x| x.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![100, 300]);
    for n in sizes {
        let r = case(n, sim, wall);
        println!(
            "{:>5} {:>9.2} {:>8.3} {:>9} {:>10.1} {:>11.1} {:>10.2e} {:>7} {:>9.2e} {:>10.2e}",
            r.n,
            r.wall_s,
            r.sim_s,
            r.substeps,
            r.contacts_per_substep,
            r.iterations_per_substep,
            r.worst_residual,
            r.unconverged,
            r.max_pen_rel,
            r.ke_final
        );
    }
}
