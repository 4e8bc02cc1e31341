fn main() -> std::process::ExitCode {
    pellet_cli::main("bedexport", bedexport::run)
}
