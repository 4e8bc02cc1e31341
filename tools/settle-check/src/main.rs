fn main() -> std::process::ExitCode {
    pellet_io::remove_temporary_files_on_signal("settle-check");
    pellet_cli::main("settle-check", settle_check::run)
}
