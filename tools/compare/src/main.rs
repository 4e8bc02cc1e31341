fn main() -> std::process::ExitCode {
    pellet_cli::main("compare", compare::run)
}
