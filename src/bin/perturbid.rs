//! The `perturbid` command line (see [`perturbid_rs::cli`]).

fn main() -> std::process::ExitCode {
    // Ctrl-C asks long work to stop at its next check; it then exits with 130 and writes nothing
    // (a second Ctrl-C while the first is honoured changes nothing). Without a handler, the
    // default action (immediate exit) remains.
    let _ = ctrlc::set_handler(perturbid_rs::interrupt::request);
    let code = perturbid_rs::cli::main_with_args(std::env::args_os());
    std::process::ExitCode::from(u8::try_from(code).unwrap_or(1))
}
