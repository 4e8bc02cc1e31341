//! Packing benchmark (plain std::time): 10 mm spheres, equilateral 10 mm
//! cylinders and 10/6/10 mm Raschig rings dropped from rest as a loose random column (random
//! orientations, bounding spheres apart) into tubes sized for a bed near 120 mm.
//!
//! Run with `cargo bench -p pellet_sim --bench pack_beds` (`make bench` runs it). Cases are
//! chosen by `PELLET_BENCH_CASES` (default: `sph:100,sph:300,sph:1000,sph:690@79.9,cyl:100,
//! cyl:300,cyl:1000,ring:300,cyl:620@91.58`: kind:N[@tube mm]; without @ the tube diameter
//! keeps the bed near 120 mm at porosity ≈ 0.4 for spheres and cylinders, 0.55 for rings).
//! `PELLET_BENCH_SIM_SECONDS` (default 1.0) and `PELLET_BENCH_WALL_SECONDS` (default 300) bound
//! each case; the table says how far a case got. Engine: density 2000 kg/m³, e = 0.5, μ = 0.3;
//! the force-level stepper with the engine's defaults, `pack --stepper acceleration`'s (the
//! recommended contact model), or the paper's contact model with `PELLET_BENCH_MODE=paper`;
//! `PELLET_BENCH_EXACT_ROWS` the largest island solved by Baraff's method and
//! `PELLET_BENCH_EXACT_FALLBACK` the largest unconverged iterative island solved again by
//! Baraff (default: the engine's, 16 and 64); `PELLET_BENCH_SOLVER=apgd` or `mprgp` the solver
//! of larger islands (default as `pack`: MPRGP for spheres, APGD otherwise); `PELLET_BENCH_TOL`
//! the solver tolerance as a factor of g and `PELLET_BENCH_NNCG=0` no NNCG step in the coupled
//! polish (default: the engine's).
//!
//! Printed per case: tube, wall and simulated time, substeps, contacts per substep (all /
//! colliding / resting), solver iterations per substep, worst residual (of every island, and
//! `res@tol` of the islands solved to the engine's tolerance: all but islands in motion, whose
//! last solve may be looser), unconverged islands,
//! max penetration, KE at the end, top centre, wall time per pellet per simulated second and
//! per pellet per substep (µs; the engine's own scaling, apart from how many substeps a case's
//! pour needs), and where the wall time went: narrow phase, collision phase, resting phase, position projection.

use pellet_sim::{
    AccelerationParams, BodyType, Container, EngineParams, IterativeSolver, Material, Pipeline, Quat, Stepper, Vec3,
    WallMaterial, World,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

// The allocator `pack` uses (see tools/pack/src/main.rs), so that the figures are pack's.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn env(name: &str, default: f64) -> f64 {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

/// Tube diameter (m) for a bed of height 0.12 m of `n` pellets of volume `v` at porosity `eps`.
fn tube_for(n: usize, v: f64, eps: f64) -> f64 {
    (4.0 * n as f64 * v / (std::f64::consts::PI * (1.0 - eps) * 0.12)).sqrt()
}

fn case(kind: &str, n: usize, tube_mm: Option<f64>, sim_seconds: f64, wall_limit: f64) {
    let ty = match kind {
        "ring" => BodyType::hollow_cylinder(0.003, 0.005, 0.005),
        "sph" => BodyType::solid_sphere(0.005),
        _ => BodyType::solid_cylinder(0.005, 0.005),
    }
    .expect("type");
    let eps = if kind == "ring" { 0.55 } else { 0.4 };
    let tube_d = tube_mm.map_or_else(|| tube_for(n, ty.volume_m3, eps), |d| d * 1e-3);
    let rb = ty.bounding_radius_m;
    // The benchmark measures the force-level stepper's phases.
    let base = EngineParams { stepper: Stepper::Acceleration, ..EngineParams::default() };
    let a = match std::env::var("PELLET_BENCH_MODE").as_deref() {
        Ok("paper") => base.acceleration.with_paper_contact_model(),
        _ => base.acceleration,
    };
    let acceleration = AccelerationParams {
        exact_solver_max_rows: env("PELLET_BENCH_EXACT_ROWS", a.exact_solver_max_rows as f64) as usize,
        exact_fallback_max_rows: env("PELLET_BENCH_EXACT_FALLBACK", a.exact_fallback_max_rows as f64) as usize,
        solver_tolerance_factor: env("PELLET_BENCH_TOL", a.solver_tolerance_factor),
        coupled_friction_nncg: env("PELLET_BENCH_NNCG", if a.coupled_friction_nncg { 1.0 } else { 0.0 }) != 0.0,
        iterative_solver: match std::env::var("PELLET_BENCH_SOLVER").as_deref() {
            Ok("apgd") => IterativeSolver::Apgd,
            Ok("mprgp") => IterativeSolver::Mprgp,
            // As `pack`: MPRGP for spheres, APGD for other shapes.
            _ if kind == "sph" => IterativeSolver::Mprgp,
            _ => IterativeSolver::Apgd,
        },
        ..a
    };
    let mut world = World::new(
        Container::tube(tube_d).expect("tube"),
        Material { density: 2000.0, cor: 0.5, friction: 0.3 },
        WallMaterial { cor: 0.5, friction: 0.3 },
        EngineParams { acceleration, ..base },
    )
    .expect("world");
    let t = world.register_type(ty).expect("register");
    let mut rng = ChaCha8Rng::seed_from_u64(2026);
    let rt = 0.5 * tube_d - 1.02 * rb;
    let mut placed: Vec<Vec3> = Vec::new();
    let mut z_top = 0.02;
    while placed.len() < n {
        let x = Vec3::new(rng.random_range(-rt..rt), rng.random_range(-rt..rt), rng.random_range(1.05 * rb..z_top));
        z_top += 0.0004;
        if x.xy().norm() > rt || placed.iter().any(|p| (p - x).norm() < 2.05 * rb) {
            continue;
        }
        let axis = Vec3::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5);
        world.add_body(t, x, Quat::from_scaled_axis(axis * 6.0), Vec3::zeros(), Vec3::zeros()).expect("add");
        placed.push(x);
    }
    let mut pipeline = Pipeline::new();
    let start = Instant::now();
    let (mut substeps, mut contacts, mut iterations, mut unconverged) = (0u64, 0u64, 0u64, 0u32);
    let (mut colliding, mut resting) = (0u64, 0u64);
    let (mut residual, mut residual_tight, mut pen): (f64, f64, f64) = (0.0, 0.0, 0.0);
    let mut phases = [0.0f64; 4];
    while world.time() < sim_seconds && start.elapsed().as_secs_f64() < wall_limit {
        let rep = world.step(1.0 / 40.0, &mut pipeline).expect("step");
        substeps += rep.substeps as u64;
        contacts += rep.contacts;
        colliding += rep.colliding;
        resting += rep.resting;
        iterations += rep.solver_iterations;
        unconverged += rep.unconverged_islands;
        residual = residual.max(rep.solver_residual);
        residual_tight = residual_tight.max(rep.solver_residual_tight);
        pen = pen.max(rep.max_penetration);
        phases.iter_mut().zip(rep.wall_seconds).for_each(|(a, b)| *a += b);
    }
    let s = substeps.max(1) as f64;
    let wall = start.elapsed().as_secs_f64();
    let pct = |x: f64| 100.0 * x / wall.max(1e-300);
    let zmax = world.bodies().iter().map(|b| b.position.z).fold(0.0, f64::max);
    println!(
        "{:>5} {:>5} {:>7.2} {:>8.1} {:>7.3} {:>9} {:>9.1} {:>6.2} {:>7.1} {:>9.1} {:>9.2e} {:>9.2e} {:>6} {:>8.2e} {:>9.2e} {:>7.3} {:>8.2} {:>8.2} {:>5.0} {:>5.0} {:>5.0} {:>5.0}",
        kind,
        n,
        tube_d * 1e3,
        wall,
        world.time(),
        substeps,
        contacts as f64 / s,
        colliding as f64 / s,
        resting as f64 / s,
        iterations as f64 / s,
        residual,
        residual_tight,
        unconverged,
        pen / 0.01,
        world.kinetic_energy(),
        zmax,
        wall / (n as f64 * world.time().max(1e-300)),
        1e6 * wall / (n as f64 * s),
        pct(phases[0]),
        pct(phases[1]),
        pct(phases[2]),
        pct(phases[3]),
    );
}

fn main() {
    let sim = env("PELLET_BENCH_SIM_SECONDS", 1.0);
    let wall = env("PELLET_BENCH_WALL_SECONDS", 300.0);
    println!(
        "{:>5} {:>5} {:>7} {:>8} {:>7} {:>9} {:>9} {:>6} {:>7} {:>9} {:>9} {:>9} {:>6} {:>8} {:>9} {:>7} {:>8} {:>8} {:>5} {:>5} {:>5} {:>5}",
        "kind",
        "N",
        "D[mm]",
        "wall[s]",
        "sim[s]",
        "substeps",
        "contacts/",
        "coll/",
        "rest/",
        "solverit/",
        "worst res",
        "res@tol",
        "unconv",
        "pen/10mm",
        "KE end[J]",
        "top[m]",
        "wall/N/s",
        "µs/N/sub",
        "%nar",
        "%col",
        "%rest",
        "%proj"
    );
    let cases = std::env::var("PELLET_BENCH_CASES").unwrap_or_else(|_| {
        "sph:100,sph:300,sph:1000,sph:690@79.9,cyl:100,cyl:300,cyl:1000,ring:300,cyl:620@91.58".into()
    });
    for c in cases.split(',') {
        let (kind, rest) = c.trim().split_once(':').unwrap_or(("cyl", c.trim()));
        let (n, tube) = match rest.split_once('@') {
            Some((n, d)) => (n.parse().expect("N"), Some(d.parse().expect("tube mm"))),
            None => (rest.parse().expect("N"), None),
        };
        case(kind, n, tube, sim, wall);
    }
}
