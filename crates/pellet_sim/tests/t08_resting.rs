//! T8: resting without drift or jitter, with spheres: (a) one sphere on the
//! floor, (b) a column of 10 spheres, (c) a sphere in a V-groove, (d) a lattice bed of 164
//! spheres in a square box.

mod common;
use common::*;
use pellet_sim::{AccelerationParams, Container, Counterpart, EngineParams, Pipeline, Vec3, WallId, World};

const R: f64 = 0.005;

fn weight(w: &World) -> f64 {
    w.bodies()[0].mass * 9.81
}

fn single(params: EngineParams) {
    let bias = params.acceleration.velocity_bias;
    let slop = params.slop_factor * 2.0 * R;
    let (mut w, t) = sphere_world(Container::tube(0.05).unwrap(), R, material(0.5, 0.3), wall(0.5, 0.3), params);
    let id = add(&mut w, t, Vec3::new(0.0, 0.0, R), Vec3::zeros(), Vec3::zeros());
    let mut p = Pipeline::new();
    let (mut dz, mut v, mut ke, mut df): (f64, f64, f64, f64) = (0.0, 0.0, 0.0, 0.0);
    let mg = weight(&w);
    for _ in 0..400 {
        w.step(1.0 / 40.0, &mut p).unwrap();
        dz = dz.max((pos(&w, id).z - R).abs());
        v = v.max(vel(&w, id).norm());
        ke = ke.max(w.kinetic_energy());
        let f: f64 = p.last_contacts().iter().map(|c| c.normal_force).sum();
        df = df.max(rel(f, mg));
    }
    eprintln!(
        "T8a bias={bias}: |dz| {dz:.2e} m (s_lop {slop:.1e}), |v| {v:.2e}, KE {ke:.2e} J, sum f rel err {df:.2e}"
    );
    assert!(dz <= slop);
    assert!(v <= 1e-6);
    assert!(ke <= 1e-12 * mg * 2.0 * R);
    assert!(df <= 1e-6);
}

#[test]
fn t8a_single_sphere_rests() {
    single(EngineParams::paper());
    single(EngineParams {
        acceleration: AccelerationParams { velocity_bias: true, ..AccelerationParams::paper() },
        ..EngineParams::paper()
    });
}

fn column(params: EngineParams, seconds: f64) {
    let bias = params.acceleration.velocity_bias;
    let slop = params.slop_factor * 2.0 * R;
    let (mut w, t) = sphere_world(Container::tube(3.0 * R).unwrap(), R, material(0.5, 0.3), wall(0.5, 0.3), params);
    let ids: Vec<_> = (0..10)
        .map(|k| add(&mut w, t, Vec3::new(0.0, 0.0, R + 2.0 * R * k as f64), Vec3::zeros(), Vec3::zeros()))
        .collect();
    let mg = weight(&w);
    let mut p = Pipeline::new();
    let (mut dz, mut v, mut df, mut proj): (f64, f64, f64, f64) = (0.0, 0.0, 0.0, 0.0);
    let steps = (seconds * 40.0) as usize;
    for _ in 0..steps {
        let rep = w.step(1.0 / 40.0, &mut p).unwrap();
        proj += rep.energy.removed_by_projection.abs();
        for (k, id) in ids.iter().enumerate() {
            dz = dz.max((pos(&w, *id).z - R - 2.0 * R * k as f64).abs());
            v = v.max(vel(&w, *id).norm());
        }
        // Interface k (below sphere k) carries the weight of spheres k..9.
        for (k, id) in ids.iter().enumerate() {
            let f: f64 = p
                .last_contacts()
                .iter()
                .filter(|c| {
                    let below = if k == 0 { Counterpart::Wall(WallId::Floor) } else { Counterpart::Body(k - 1) };
                    (c.contact.a == id.0 as usize && c.contact.b == below)
                        || (k > 0 && c.contact.a == k - 1 && c.contact.b == Counterpart::Body(k))
                })
                .map(|c| c.normal_force)
                .sum();
            df = df.max(rel(f, (10 - k) as f64 * mg));
        }
    }
    eprintln!(
        "T8b bias={bias}: |dz| {dz:.2e} m, |v| {v:.2e}, interface sums rel err {df:.2e}, projection work {proj:.2e} J"
    );
    assert!(dz <= slop);
    assert!(v <= 1e-6);
    assert!(df <= 1e-6);
}

#[test]
fn t8b_column_of_ten_spheres() {
    column(EngineParams::paper(), 10.0);
    column(
        EngineParams {
            acceleration: AccelerationParams { velocity_bias: true, ..AccelerationParams::paper() },
            ..EngineParams::paper()
        },
        10.0,
    );
}

#[test]
fn t8c_sphere_in_v_groove() {
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let z0 = 0.02;
    let n1 = Vec3::new(s, 0.0, s);
    let n2 = Vec3::new(-s, 0.0, s);
    let bottom = Vec3::new(0.0, 0.0, z0);
    let c =
        Container::tube(0.1).unwrap().with_plane(n1, n1.dot(&bottom)).unwrap().with_plane(n2, n2.dot(&bottom)).unwrap();
    let (mut w, t) = sphere_world(c, R, material(0.5, 0.0), wall(0.5, 0.0), EngineParams::paper());
    let id = add(&mut w, t, Vec3::new(0.0, 0.0, z0 + R / s), Vec3::zeros(), Vec3::zeros());
    let mg = weight(&w);
    let mut p = Pipeline::new();
    run(&mut w, &mut p, 1.0 / 40.0, 40);
    let forces: Vec<f64> = p.last_contacts().iter().map(|c| c.normal_force).collect();
    eprintln!("T8c: forces/mg {:?} (want 0.70711 each)", forces.iter().map(|f| f / mg).collect::<Vec<_>>());
    assert_eq!(forces.len(), 2);
    for f in forces {
        assert!(rel(f / mg, s) <= 1e-6);
    }
    assert!(vel(&w, id).norm() <= 1e-6);
}

/// 5×5 / 4×4 alternating layers (8 layers, 164 spheres) touching exactly in a square box.
fn lattice(params: EngineParams) -> (World, Pipeline) {
    let d = 2.0 * R;
    let half = 2.5 * d;
    let c = Container::tube(12.0 * d)
        .unwrap()
        .with_plane(Vec3::x(), -half)
        .unwrap()
        .with_plane(-Vec3::x(), -half)
        .unwrap()
        .with_plane(Vec3::y(), -half)
        .unwrap()
        .with_plane(-Vec3::y(), -half)
        .unwrap();
    let (mut w, t) = sphere_world(c, R, material(0.5, 0.0), wall(0.5, 0.0), params);
    let h = d * std::f64::consts::FRAC_1_SQRT_2;
    for layer in 0..8 {
        let (n, off) = if layer % 2 == 0 { (5, 0.0) } else { (4, 0.5 * d) };
        for i in 0..n {
            for j in 0..n {
                let x = -2.0 * d + off + d * i as f64;
                let y = -2.0 * d + off + d * j as f64;
                add(&mut w, t, Vec3::new(x, y, R + h * layer as f64), Vec3::zeros(), Vec3::zeros());
            }
        }
    }
    assert_eq!(w.bodies().len(), 164);
    let mut p = Pipeline::new();
    w.step(1e-5, &mut p).unwrap();
    (w, p)
}

/// (floor force / weight − 1, max body acceleration, rows, residual, iterations)
fn lattice_stats(w: &World, p: &Pipeline) -> (f64, f64, usize, f64) {
    let n = w.bodies().len();
    let mut force = vec![Vec3::zeros(); n];
    let mut floor = 0.0;
    for c in p.last_contacts() {
        let f = c.contact.normal * c.normal_force;
        force[c.contact.a] += f;
        match c.contact.b {
            Counterpart::Body(b) => force[b] -= f,
            Counterpart::Wall(WallId::Floor) => floor += c.normal_force,
            _ => {}
        }
    }
    let g = Vec3::new(0.0, 0.0, -9.81);
    let acc = w.bodies().iter().zip(&force).map(|(b, f)| (g + f / b.mass).norm()).fold(0.0, f64::max);
    let weight: f64 = w.bodies().iter().map(|b| b.mass * 9.81).sum();
    (floor / weight - 1.0, acc, p.last_contacts().len(), 0.0)
}

#[test]
fn t8d_lattice_bed_apgd() {
    let params = EngineParams::paper();
    let tol = params.solver_tolerance();
    let (w, p) = lattice(params);
    let (floor_err, acc, rows, _) = lattice_stats(&w, &p);
    eprintln!("T8d default tolerance: {rows} contacts, floor force rel err {floor_err:.2e}, max body accel {acc:.2e} (10 tol_r = {:.2e})", 10.0 * tol);
    assert!(rows >= 700);
    assert!(acc <= 10.0 * tol);
}

#[test]
fn t8d_lattice_bed_tight_tolerance() {
    // The floor force equals the weight to 1e-6 once the solver is run to a tight residual.
    let params = EngineParams {
        acceleration: AccelerationParams {
            solver_tolerance_factor: 1e-8,
            apgd_max_iterations: 5000,
            pgs_max_iterations: 20000,
            ..AccelerationParams::paper()
        },
        ..EngineParams::paper()
    };
    let (w, p) = lattice(params);
    let (floor_err, acc, rows, _) = lattice_stats(&w, &p);
    eprintln!("T8d tight tolerance: {rows} contacts, floor force rel err {floor_err:.2e}, max body accel {acc:.2e}");
    assert!(floor_err.abs() <= 1e-6);
}
