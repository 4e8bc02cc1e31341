fn main() -> std::process::ExitCode {
    pellet_cli::main("paper-report", paper_report::run)
}
