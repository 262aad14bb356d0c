//! `cargo xtask derive`: the workspace's call of `lagrange-derive` (the same code, as a
//! library), and the check of it that `cargo xtask ci` runs.
//!
//! ```text
//! cargo xtask derive SPEC.py [--out FILE.rs] [--name TypeName] [--tests] [--force] [--check]
//! cargo xtask derive --update FILE.rs...
//! cargo xtask derive --check             the workspace's check, below
//! ```
//!
//! `--check` alone: every committed mechanism of [`GENERATED`] regenerates, from the spec and
//! options its header records, to the same bytes ([`lagrange_derive::check_file`]); every
//! spec of [`refusals::BAD_INPUT`] and every bad use of the command is refused with a clear
//! message, a non-zero status and no file touched; and the odd-name specs of `derive/odd/`
//! derive into a scratch crate outside the workspace that passes clippy `-D warnings`,
//! rustfmt and its generated tests ([`odd_names`]).

mod odd_names;
mod refusals;

use crate::cmd;
use lagrange_derive::Mode;

/// The committed mechanisms (relative to the workspace root), each generated with `--tests`.
pub const GENERATED: [&str; 6] = [
    "derive/generated/src/pendulum.rs",
    "derive/generated/src/double_pendulum.rs",
    "derive/generated/src/spring_cart_pendulum.rs",
    "derive/generated/src/triple_pendulum.rs",
    "derive/generated/src/kapitza_pendulum.rs",
    "derive/generated/src/cartesian_pendulum.rs",
];

/// `cargo xtask derive ARGS`: `lagrange-derive ARGS`, except `--check` alone.
pub fn run(args: &[String]) -> Result<(), String> {
    if args == ["--check"] {
        return check();
    }
    lagrange_derive::run(args)
}

/// `cargo xtask derive --check`: every part runs, and every failure is reported.
pub fn check() -> Result<(), String> {
    println!("$ cargo xtask derive --check");
    let root = cmd::project_root();
    let started = std::time::Instant::now();
    let mut failures = Vec::new();
    for file in GENERATED {
        let step = std::time::Instant::now();
        match lagrange_derive::check_file(&root.join(file), Mode::Check) {
            Ok(()) => println!(
                "   {file}: regenerated, identical ({:.1} s)",
                step.elapsed().as_secs_f64()
            ),
            Err(e) => failures.push(e),
        }
    }
    failures.extend(refusals::check(&root));
    failures.extend(odd_names::check(&root));
    println!("derive --check: {:.0} s", started.elapsed().as_secs_f64());
    if failures.is_empty() {
        println!("derive --check: all passed");
        Ok(())
    } else {
        Err(format!("derive --check:\n{}", failures.join("\n")))
    }
}
