//! Diagnostic (not a proof): a mixed pour (cylinders and rings alternating, 40 mm tube, paper
//! mode) printing the energy ledger per 1/40 s step: ΔE, the logged removals, the resting
//! normal work, the ledger residual RES = ΔE + removals − resting work, penetration before and
//! after projection, substeps, rewinds, unconverged islands and the solver residual.
//! `NP=40 SECS=0.3 cargo test -p pellet_sim --release --test diag_pour_ledger -- --ignored --nocapture`
//! (NP pellets, default 12; SECS, default 1.0; SEED, default 7).

mod common;
use common::*;

#[test]
#[ignore]
fn diag_pour_ledger() {
    let n: usize = std::env::var("NP").ok().and_then(|s| s.parse().ok()).unwrap_or(12);
    let secs: f64 = std::env::var("SECS").ok().and_then(|s| s.parse().ok()).unwrap_or(1.0);
    let seed: u64 = std::env::var("SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(7);
    let mut w = mixed_pour(n, seed);
    let mut p = pellet_sim::Pipeline::new();
    let e0 = w.kinetic_energy() + w.potential_energy();
    let mut prev = e0;
    let (mut cum_res, mut pen) = (0.0, 0.0f64);
    for s in 0..(secs * 40.0) as usize {
        let r = w.step(1.0 / 40.0, &mut p).unwrap();
        pen = pen.max(r.max_penetration);
        let e = r.energy.total();
        let l = &r.energy;
        let res = (e - prev) + l.removed_by_collisions + l.removed_by_friction + l.removed_by_projection
            - l.resting_normal_work;
        cum_res += res;
        println!("s {s:3} E {e:.6e} dE {:+.3e} coll {:.3e} fric {:+.3e} proj {:+.3e} Wn {:+.3e} bound {:.2e} RES {:+.3e} cum {:+.3e} pen {:.2e} after {:.2e} sub {} rew {} guard {} unconv {} resid {:.1e}",
            e - prev, l.removed_by_collisions, l.removed_by_friction, l.removed_by_projection, l.resting_normal_work, l.resting_work_bound, res, cum_res, r.max_penetration, r.max_penetration_after_projection, r.substeps, r.rewinds, r.guard_events, r.unconverged_islands, r.solver_residual);
        prev = e;
    }
    println!(
        "final E {:.6e} (E0 {e0:.6e}) KE {:.3e} max pen {pen:.2e} cum residual {cum_res:+.3e}",
        prev,
        w.kinetic_energy()
    );
}
