fn main() -> std::process::ExitCode {
    pellet_io::remove_temporary_files_on_signal("compare");
    pellet_cli::main("compare", compare::run)
}
