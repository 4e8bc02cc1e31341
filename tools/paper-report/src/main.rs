fn main() -> std::process::ExitCode {
    pellet_io::remove_temporary_files_on_signal("paper-report");
    pellet_cli::main("paper-report", paper_report::run)
}
