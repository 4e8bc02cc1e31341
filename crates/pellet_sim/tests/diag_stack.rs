//! Diagnostic, not a test: a stack of NS (5) cylinders in recommended mode, logged per step of
//! DT (1/40 s) for STEPS (80) steps: substeps, solver iterations, unconverged islands, residual,
//! each body's |v| and |ω|, and the number of loaded contacts (FORCES=1 prints each one's normal
//! and friction force). It shows contact keys that swap between substeps, which lose their warm
//! start (see the sort of a patch's hits in `geometry/patch.rs`). Run:
//! `DT=2.5e-4 STEPS=100 cargo test -p pellet_sim --release --test diag_stack -- --ignored --nocapture`
mod common;
use common::*;
use pellet_sim::EngineParams;

#[test]
#[ignore]
fn diag_stack() {
    let n: usize = std::env::var("NS").map(|s| s.parse().unwrap()).unwrap_or(5);
    let (mut w, ids) = cylinder_stack(n, EngineParams::recommended());
    let mut p = pellet_sim::Pipeline::new();
    let steps: usize = std::env::var("STEPS").map(|s| s.parse().unwrap()).unwrap_or(80);
    let dt: f64 = std::env::var("DT").map(|s| s.parse().unwrap()).unwrap_or(1.0 / 40.0);
    for s in 0..steps {
        let r = w.step(dt, &mut p).unwrap();
        let mut line = format!(
            "{s:3} sub {} it {} un {} res {:.1e} |",
            r.substeps, r.solver_iterations, r.unconverged_islands, r.solver_residual
        );
        for id in &ids {
            let b = w.body(*id).unwrap();
            line += &format!(" v{:.1e} w{:.1e}", b.velocity().norm(), b.angular_velocity().norm());
        }
        let nf: Vec<String> = p
            .last_contacts()
            .iter()
            .filter(|c| c.normal_force > 0.0)
            .map(|c| format!("{:.3e}/{:.1e}", c.normal_force, c.friction_force.norm()))
            .collect();
        println!("{line} | {}", nf.len());
        if std::env::var("FORCES").is_ok() {
            println!("   {}", nf.join(" "));
        }
    }
}
