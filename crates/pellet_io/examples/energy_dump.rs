fn main() {
    let p = std::env::args().nth(1).unwrap();
    let b = std::fs::read(&p).unwrap();
    let t = pellet_io::read_trajectory(&b, &p).unwrap();
    println!("time pellets substeps iterations resting colliding ke");
    for e in &t.energy {
        println!(
            "{:.4} {} {} {} {} {} {:.3e} {:.3e} {:.2e}",
            e.time_s,
            e.pellets,
            e.substeps,
            e.solver_iterations,
            e.resting_contacts,
            e.colliding_contacts,
            e.kinetic_translational_j + e.kinetic_rotational_j,
            e.max_speed_m_s,
            e.solver_residual
        );
    }
}
