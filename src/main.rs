fn main() -> std::process::ExitCode {
    infiniterra::cli::main()
}
