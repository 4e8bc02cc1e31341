fn main() -> std::process::ExitCode {
    pellet_cli::main("mkpellet", mkpellet::run)
}
