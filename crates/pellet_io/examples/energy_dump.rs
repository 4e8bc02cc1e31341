//! Prints a trajectory's energy channel, one line per recorded step, for diagnosing where a
//! pack run spends its solver work (docs/engine.md, Speed):
//! `cargo run --release -p pellet_io --example energy_dump -- bed.mcap`.
//! Columns: time (s), pellets, substeps, solver iterations (resting and collision phases,
//! Baraff pivots included), resting contacts, colliding contacts, kinetic energy (J), fastest
//! pellet (m/s), largest resting-solver residual (m/s²). A truncated file prints what it holds.

fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("energy_dump: usage: energy_dump BED.mcap");
        std::process::exit(2);
    };
    let trajectory = std::fs::read(&path)
        .map_err(|e| e.to_string())
        .and_then(|bytes| pellet_io::read_trajectory(&bytes, &path).map_err(|e| e.to_string()));
    let trajectory = match trajectory {
        Ok(t) => t,
        Err(e) => {
            eprintln!("energy_dump: {e}");
            std::process::exit(2);
        }
    };
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    // A closed pipe (`| head`) ends the listing quietly.
    if writeln!(out, "time_s pellets substeps iterations resting colliding ke_j max_speed_m_s residual_m_s2").is_err() {
        return;
    }
    for e in &trajectory.energy {
        let line = writeln!(
            out,
            "{:.4} {} {} {} {} {} {:.3e} {:.3e} {:.2e}",
            e.time_s,
            e.pellets,
            e.substeps,
            e.solver_iterations,
            e.resting_contacts,
            e.colliding_contacts,
            e.kinetic_j(),
            e.max_speed_m_s,
            e.solver_residual
        );
        if line.is_err() {
            return;
        }
    }
}
