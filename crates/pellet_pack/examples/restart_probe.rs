//! A probe of the engine: restarts it from one frame of a `pack` trajectory, every pellet at
//! rest, and prints per step what the resting phase did and how far the bed moves. A bed that a
//! perfect solver would hold still (it was nearly at rest in the trajectory) shows whether the
//! solver's answers make it creep. Run:
//!
//! `TRAJ=bed.mcap AT=6.0 SECS=0.5 cargo run --release -p pellet_pack --example restart_probe`
//!
//! `TRAJ` is the trajectory, `AT` the frame time (s, nearest frame), `SECS` the simulated time to
//! run, `STEP` the engine call's step (s, default 1/40); the stepper is the trajectory's, or `VELOCITY` / `ACCELERATION` chooses one; `EPS_P`, `COR`, `FRICTION`, `EXACT_FALLBACK`, `APGD_IT`, `PGS_IT`, `TOL` (solver tolerance / g), `MAX_SWEEPS`, `VTOL` (the velocity solve's tolerance / εp), `PATCH` (the point contacts' patch radius / d) change one
//! setting, and `CONTACTS` lists the fastest pellet's contacts (or pellet `BODY`'s, whose motion is
//! printed too) after every step; `PAIRS` counts contact points per pair; `CHECKPOINT` goes on
//! from the trajectory's last checkpoint (velocities and warm starts included) instead. The tube and
//! pellet are the trajectory's; materials and engine parameters are pack's defaults.

#[path = "../tests/common/mod.rs"]
mod common;

use pellet_io::read_trajectory;
use pellet_sim::{Pipeline, Vec3};

fn env_f64(name: &str, default: f64) -> f64 {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

fn main() {
    let Ok(path) = std::env::var("TRAJ") else {
        eprintln!("restart_probe: set TRAJ to a pack trajectory (and AT, SECS; see the file's header)");
        std::process::exit(2);
    };
    let bytes = std::fs::read(&path).expect("trajectory readable");
    let traj = read_trajectory(&bytes, &path).expect("a pack trajectory");
    let at = env_f64("AT", traj.frames.last().map_or(0.0, |f| f.time_s));
    let secs = env_f64("SECS", 0.5);
    let frame = traj
        .frames
        .iter()
        .min_by(|a, b| (a.time_s - at).abs().total_cmp(&(b.time_s - at).abs()))
        .expect("frames recorded");
    let pellet = pellet_io::decode_pellet(&traj.pellet_files[0], "attached pellet").expect("pellet attached").pellet;
    let tube = traj.tube.expect("tube attached");
    let config = common::pack_config(tube.diameter * 1e3, frame.positions.len() as u32, |o| {
        o.resting_band = std::env::var("EPS_P").ok().map(|v| v.parse().unwrap());
        o.cor = std::env::var("COR").ok().map(|v| v.parse().unwrap());
        o.friction = std::env::var("FRICTION").ok().map(|v| v.parse().unwrap());
    });
    let mut params = pellet_pack::engine_params(&config);
    if let Ok(v) = std::env::var("EXACT_FALLBACK") {
        params.acceleration.exact_fallback_max_rows = v.parse().unwrap();
    }
    if let Ok(v) = std::env::var("APGD_IT") {
        params.acceleration.apgd_max_iterations = v.parse().unwrap();
    }
    if let Ok(v) = std::env::var("PGS_IT") {
        params.acceleration.pgs_max_iterations = v.parse().unwrap();
    }
    if let Ok(v) = std::env::var("TOL") {
        params.acceleration.solver_tolerance_factor = v.parse().unwrap();
    }
    // The trajectory's own stepper (runs recorded before the choice were the force-level
    // stepper's), unless VELOCITY or ACCELERATION asks for one.
    let recorded = traj.run.get("config").and_then(|c| serde_json::from_str::<pellet_pack::PackConfig>(c).ok());
    params.stepper = recorded.map_or(pellet_sim::Stepper::Acceleration, |c| c.stepper);
    if std::env::var("VELOCITY").is_ok() {
        params.stepper = pellet_sim::Stepper::Velocity;
    }
    if std::env::var("ACCELERATION").is_ok() {
        params.stepper = pellet_sim::Stepper::Acceleration;
    }
    if let Ok(v) = std::env::var("VTOL") {
        params.velocity.tolerance_factor = v.parse().unwrap();
    }
    if let Ok(v) = std::env::var("MAX_SWEEPS") {
        params.velocity.max_sweeps = v.parse().unwrap();
    }
    if let Ok(v) = std::env::var("PATCH") {
        params.velocity.patch_radius = v.parse().unwrap();
    }

    let poses: Vec<([f64; 3], [f64; 4])> =
        frame.positions.iter().copied().zip(frame.orientations.iter().copied()).collect();
    let mut world = common::restart_world(&config, params, &pellet, &poses);
    println!(
        "restart of {path} at t = {:.3} s: {} pellets, D = {:.2} mm",
        frame.time_s,
        frame.positions.len(),
        tube.diameter * 1e3
    );
    let mut pipeline = Pipeline::new();
    if std::env::var("CHECKPOINT").is_ok() {
        // The run's last checkpoint instead: velocities, time and warm starts as the run had
        // them, so that the steps are the run's own.
        let bytes = traj.checkpoint.as_ref().expect("the trajectory has a checkpoint");
        let c = pellet_pack::Checkpoint::decode(bytes, &path).expect("a readable checkpoint");
        world.restore(c.world).expect("the checkpoint fits the world");
        pipeline = Pipeline::with_warm_state(&c.warm, &c.impulses).with_manifolds(c.manifolds);
        println!("continuing from its last checkpoint at t = {:.4} s", world.time());
    }
    let start: Vec<Vec3> = world.bodies().iter().map(|b| b.position).collect();
    let step = env_f64("STEP", 1.0 / 40.0);
    let clock = std::time::Instant::now();
    let end = world.time() + secs;
    while world.time() < end - 1e-9 {
        let e0 = world.energy().total();
        let r = world.step(step, &mut pipeline).unwrap();
        let (de, l) = (world.energy().total() - e0, r.energy);
        println!(
            "  energy: ΔE {:+.2e} J, removed by collisions {:.2e}, friction {:.2e}, projection {:.2e}; unlogged {:+.2e} J",
            de,
            l.removed_by_collisions,
            l.removed_by_friction,
            l.removed_by_projection,
            de + l.removed_by_collisions + l.removed_by_friction + l.removed_by_projection
        );
        let moved = world.bodies().iter().zip(&start).map(|(b, p0)| (b.position - p0).norm()).fold(0.0, f64::max);
        let vmax = world.bodies().iter().map(|b| b.velocity().norm()).fold(0.0, f64::max);
        let (fast, body) = world
            .bodies()
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.velocity().norm().total_cmp(&b.1.velocity().norm()))
            .unwrap();
        println!(
            "  fastest: #{fast} at z {:.1} mm, v {:?} mm/s, ω {:?} rad/s; colliding {} impulses {} friction drops {} dt {:.1e}..{:.1e}",
            body.position.z * 1e3,
            (body.velocity() * 1e3).as_slice().iter().map(|v| format!("{v:.2}")).collect::<Vec<_>>(),
            body.angular_velocity().as_slice().iter().map(|v| format!("{v:.3}")).collect::<Vec<_>>(),
            r.colliding,
            r.impulses,
            r.friction_guard_drops,
            r.dt_min,
            r.dt_max
        );
        if let Some(k) = std::env::var("BODY").ok().and_then(|v| v.parse::<usize>().ok()) {
            let b = &world.bodies()[k];
            println!(
                "  #{k}: x {:?} mm, v {:.2e} m/s, ω {:?} rad/s",
                (b.position * 1e3).as_slice().iter().map(|v| format!("{v:.5}")).collect::<Vec<_>>(),
                b.velocity().norm(),
                b.angular_velocity().as_slice().iter().map(|v| format!("{v:.4}")).collect::<Vec<_>>(),
            );
        }
        if std::env::var("PAIRS").is_ok() {
            // Contact points per pair (pellet–pellet and pellet–wall), and how many distinct
            // normals (patches) and loaded points the pairs with the most points have.
            let mut pairs: std::collections::BTreeMap<(usize, String), Vec<&pellet_sim::ContactRecord>> =
                Default::default();
            for rec in pipeline.last_contacts() {
                pairs.entry((rec.contact.a, format!("{:?}", rec.contact.b))).or_default().push(rec);
            }
            let mut hist = [0usize; 12];
            let (mut patches, mut loaded, mut many) = (0usize, 0usize, 0usize);
            for recs in pairs.values() {
                hist[recs.len().min(11)] += 1;
                if recs.len() >= 5 {
                    many += 1;
                    let mut normals: Vec<Vec3> = Vec::new();
                    for r in recs {
                        if !normals.iter().any(|n| n.dot(&r.contact.normal) > 0.9998) {
                            normals.push(r.contact.normal);
                        }
                    }
                    patches += normals.len();
                    loaded += recs.iter().filter(|r| r.normal_force > 0.0).count();
                }
            }
            if let Some(recs) = pairs.values().filter(|r| r.len() >= 6).nth(3) {
                for r in recs {
                    let c = &r.contact;
                    println!(
                        "    {}–{:?} key {:x} n [{:.3} {:.3} {:.3}] gap {:.2e} f {:.1e}",
                        c.a, c.b, c.key.feature, c.normal.x, c.normal.y, c.normal.z, c.gap, r.normal_force
                    );
                }
            }
            println!(
                "  pairs {} by points (0..11+): {:?}; pairs with >= 5 points: {many}, {:.1} patches and {:.1} loaded points each",
                pairs.len(),
                &hist[1..],
                patches as f64 / many.max(1) as f64,
                loaded as f64 / many.max(1) as f64
            );
        }
        if std::env::var("CONTACTS").is_ok() {
            let vel = |k: usize, r: &Vec3| {
                let b = &world.bodies()[k];
                b.velocity() + b.angular_velocity().cross(r)
            };
            let who = std::env::var("BODY").ok().and_then(|v| v.parse::<usize>().ok()).unwrap_or(fast);
            for rec in pipeline.last_contacts().iter().filter(|r| r.contact.a == who || r.contact.b_body() == Some(who))
            {
                let c = &rec.contact;
                let u = vel(c.a, &c.lever_a) - c.b_body().map_or(Vec3::zeros(), |k| vel(k, &c.lever_b));
                let vn = c.normal.dot(&u);
                println!(
                    "    {}–{:?} key {:x} pt z {:.2} mm n [{:.2} {:.2} {:.2}] gap {:.2e} m vn {:+.2e} slip {:.2e} m/s f {:.2e} N fric {:.2e} N",
                    c.a,
                    c.b,
                    c.key.feature,
                    c.point.z * 1e3,
                    c.normal.x,
                    c.normal.y,
                    c.normal.z,
                    c.gap,
                    vn,
                    (u - c.normal * vn).norm(),
                    rec.normal_force,
                    rec.friction_force.norm()
                );
            }
        }
        println!(
            "t {:.3} KE {:.2e} J vmax {:.2e} m/s moved {:.2e} m | substeps {} it/substep {:.0} unconverged {} largest {} residual {:.2e} loaded {} warm {} pen {:.2e} wall {:.1} s (narrow phase {:.2}, collisions {:.2}, solve {:.2}, projection {:.2} s)",
            world.time(),
            world.kinetic_energy(),
            vmax,
            moved,
            r.substeps,
            r.solver_iterations as f64 / r.substeps.max(1) as f64,
            r.unconverged_islands,
            r.largest_island,
            r.solver_residual,
            r.loaded_contacts,
            r.loaded_warm,
            r.max_penetration,
            clock.elapsed().as_secs_f64(),
            r.wall_seconds[0],
            r.wall_seconds[1],
            r.wall_seconds[2],
            r.wall_seconds[3]
        );
    }
}
