fn main() -> std::process::ExitCode {
    pellet_cli::main("pack", pack::run)
}
