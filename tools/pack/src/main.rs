// mimalloc keeps freed pages for reuse: under glibc's malloc the engine's per-substep buffers
// (rows, friction entries: 100s of kB per island) were returned to the kernel and faulted in
// again every substep, 8-13 % of a 690-sphere bed's CPU time (measured with the force-level
// stepper).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> std::process::ExitCode {
    pellet_cli::main("pack", pack::run)
}
