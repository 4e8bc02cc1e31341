fn main() -> std::process::ExitCode {
    pellet_io::remove_temporary_files_on_signal("bedexport");
    pellet_cli::main("bedexport", bedexport::run)
}
