fn main() -> std::process::ExitCode {
    pellet_io::remove_temporary_files_on_signal("mkpellet");
    pellet_cli::main("mkpellet", mkpellet::run)
}
