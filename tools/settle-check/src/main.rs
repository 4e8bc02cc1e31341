fn main() -> std::process::ExitCode {
    pellet_cli::main("settle-check", settle_check::run)
}
