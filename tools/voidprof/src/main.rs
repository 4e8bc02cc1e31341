fn main() -> std::process::ExitCode {
    pellet_io::remove_temporary_files_on_signal("voidprof");
    pellet_cli::main("voidprof", voidprof::run)
}
