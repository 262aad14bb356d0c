//! `lagrange-derive`: the command. Everything it does is in the library, shared with the
//! lagrange workspace's `cargo xtask derive`.

use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match lagrange_derive::run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{e}");
            ExitCode::FAILURE
        }
    }
}
