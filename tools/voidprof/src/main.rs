fn main() -> std::process::ExitCode {
    pellet_cli::main("voidprof", voidprof::run)
}
