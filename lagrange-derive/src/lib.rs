//! # lagrange-derive
//!
//! The origin's workflow as a command: write the kinetic energy `T` and the potential energy
//! `V` of a mechanism with SymPy in a spec file, let SymPy derive the Euler-Lagrange equations,
//! and get a `no_std` Rust file that makes it a `lagrange_core::Mechanism`.
//!
//! ```text
//! lagrange-derive SPEC.py --out src/my_mechanism.rs [--name TypeName] [--tests] [--force]
//! lagrange-derive SPEC.py --out src/my_mechanism.rs --check
//! lagrange-derive --update src/my_mechanism.rs...
//! lagrange-derive --check src/my_mechanism.rs...
//! ```
//!
//! The derivation is a Python script carried inside this crate ([`SCRIPT`]). The first run
//! makes a virtual environment with the pinned SymPy ([`PACKAGES`]) in the user's cache folder
//! ([`environment`]), with the `python3` it finds; later runs reuse it. The output is
//! formatted by `rustfmt` and written only when every step succeeded, never over the spec and
//! never over a file that this tool did not generate (unless `--force`). See the README (and
//! `lagrange-derive --help`) for the spec's keys and the naming rule.
//!
//! The library is the command's code, shared with the lagrange workspace's
//! `cargo xtask derive`: [`run`] takes the command line.

mod args;
pub mod environment;
mod generate;
pub mod header;
mod output;
mod run;

pub use args::{Job, Mode, HELP};
pub use generate::{derive, rustfmt};
pub use output::{first_difference, write_atomically};
pub use run::{check_file, run};

/// The derivation script (`derive.py`): read by Python from its standard input.
pub const SCRIPT: &str = include_str!("../derive.py");

/// SymPy and its one dependency, pinned: the same spec gives the same bytes.
pub const PACKAGES: [&str; 2] = ["sympy==1.14.0", "mpmath==1.3.0"];
