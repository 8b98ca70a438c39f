//! The `perturbid` command line (see [`perturbid_rs::cli`]).

fn main() -> std::process::ExitCode {
    let code = perturbid_rs::cli::main_with_args(std::env::args_os());
    std::process::ExitCode::from(u8::try_from(code).unwrap_or(1))
}
