//! The command line: what `lagrange-derive` is asked, and its `--help`.

/// `lagrange-derive --help`.
pub const HELP: &str = "\
lagrange-derive: a no_std lagrange-core mechanism from T and V written with SymPy

USAGE:
    lagrange-derive SPEC.py [--out FILE.rs] [--name TypeName] [--tests] [--force]
    lagrange-derive SPEC.py --out FILE.rs --check [--name TypeName] [--tests]
    lagrange-derive --update FILE.rs...
    lagrange-derive --check FILE.rs...

    SPEC.py          the spec: a Python file that defines q, params, T, V (and Q, phi, ...)
    --out FILE.rs    where the Rust file goes; never the spec, and never a file that
                     lagrange-derive did not generate unless --force (without --out: stdout,
                     and the header takes the file to be in the current folder)
    --name TypeName  the Rust type's name (else the spec's `name`, else its file name)
    --tests          add a test module: the closed form against the automatic path of its own
                     T and V, in f64 and f32 (needs only lagrange-core)
    --force          overwrite --out even when lagrange-derive did not generate it
    --check          write nothing; fail when the file differs from what its spec gives
    --update         regenerate each file from its spec, as its header records it (from any
                     folder: the spec's path in the header is relative to the file)

THE SPEC (module-level names):
    q        the coordinates: dynamicsymbols(\"x th\"), or Function(\"x\")(t) for a time
             t = symbols(\"t\", ...) of your own (any assumptions, e.g. positive=True)
    params   {symbol: default} or {symbol: (default, kind[, \"description, unit\"])},
             kind \"positive\", \"non_negative\" or \"finite\"; the order is the constructor's
    T, V     kinetic and potential energy (T quadratic in the velocities); time may enter
    Q        optional: generalized non-conservative forces, one per coordinate
    phi      optional: holonomic constraint rows phi(q) = 0
    links    optional: each link's frame [(x, y, angle), ...] as functions of q: the type
             then implements Links (shapes on its links in a lagrange-world World)
    name, doc, ranges, simplify   optional: type name, docs, test ranges, trigsimp on/off
    Functions: + - * /, integer and half-integer powers, sqrt, sin, cos, tan, exp, log,
    atan2, pi.

NAMES:
    Any SymPy name for a parameter or a coordinate (M, m, s, I, theta_1, a Greek letter).
    An ASCII identifier keeps its spelling (M stays M); others are spelled out (θ₂ is
    theta_2, ẋ is x_dot); a Rust keyword gets a trailing _ (type_), and so does a parameter
    named like a method of the mechanism (energy_, new_). Two names that become one are
    refused, naming both. The generated code's own names give way to yours.
    Reserved: the spec's keys above as Python variables, and the time's name (it is the
    time, not a parameter).

The first run makes a Python environment with SymPy 1.14.0 in the user's cache folder
(LAGRANGE_DERIVE_CACHE to choose another), with the python3 it finds (LAGRANGE_DERIVE_PYTHON
to choose one). The output is formatted with rustfmt.
";

/// What to do with the spec's derivation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Write the file (or stdout).
    Write,
    /// Compare with the file, write nothing.
    Check,
}

/// One derivation: a spec, its options and where it goes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Job {
    /// The spec's path.
    pub spec: String,
    /// The output's path (`None`: stdout).
    pub out: Option<String>,
    /// The type's name, when given on the command line.
    pub name: Option<String>,
    /// Whether a test module is added.
    pub tests: bool,
    /// Whether `out` may be overwritten though it was not generated.
    pub force: bool,
    /// Write or check.
    pub mode: Mode,
}

/// A parsed command line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Command {
    /// `--help`.
    Help,
    /// `--version`.
    Version,
    /// Derive one spec.
    Derive(Job),
    /// Regenerate (`Write`) or check (`Check`) generated files from their headers.
    Files(Vec<String>, Mode),
}

/// The usage lines, for errors.
const USAGE: &str =
    "usage: lagrange-derive SPEC.py [--out FILE.rs] [--name TypeName] [--tests] [--force] [--check]
       lagrange-derive --update FILE.rs...  |  --check FILE.rs...  |  --help";

/// Parses the arguments (without the program's name).
pub fn parse(args: &[String]) -> Result<Command, String> {
    let mut positional = Vec::new();
    let (mut out, mut name) = (None, None);
    let (mut tests, mut force, mut check, mut update) = (false, false, false, false);
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "-h" | "--help" => return Ok(Command::Help),
            "-V" | "--version" => return Ok(Command::Version),
            "--out" | "-o" => out = Some(value(&mut it, a)?),
            "--name" => name = Some(value(&mut it, a)?),
            "--tests" => tests = true,
            "--force" => force = true,
            "--check" => check = true,
            "--update" => update = true,
            s if s.starts_with('-') && s != "-" => {
                return Err(format!("error: unknown option `{s}`\n{USAGE}"))
            }
            s => positional.push(s.to_string()),
        }
    }
    if update || (check && out.is_none()) {
        if update && check {
            return Err(format!(
                "error: --update and --check exclude each other\n{USAGE}"
            ));
        }
        if out.is_some() || name.is_some() || tests || force {
            return Err(format!(
                "error: --update and --check FILE.rs... take the spec and options from each \
                 file's header: no --out, --name, --tests or --force\n{USAGE}"
            ));
        }
        if positional.is_empty() {
            return Err(format!("error: name the generated files\n{USAGE}"));
        }
        let mode = if update { Mode::Write } else { Mode::Check };
        return Ok(Command::Files(positional, mode));
    }
    let spec = match positional.as_slice() {
        [spec] => spec.clone(),
        [] => return Err(format!("error: no spec given\n{USAGE}")),
        [_, extra, ..] => return Err(format!("error: unexpected argument `{extra}`\n{USAGE}")),
    };
    let mode = if check { Mode::Check } else { Mode::Write };
    Ok(Command::Derive(Job {
        spec,
        out,
        name,
        tests,
        force,
        mode,
    }))
}

/// The value after option `a`.
fn value(it: &mut core::slice::Iter<'_, String>, a: &str) -> Result<String, String> {
    it.next()
        .cloned()
        .ok_or_else(|| format!("error: {a} needs a value\n{USAGE}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strings(a: &[&str]) -> Vec<String> {
        a.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn a_spec_with_its_options() {
        let c = parse(&strings(&[
            "s.py", "--out", "a.rs", "--tests", "--name", "A",
        ]));
        assert_eq!(
            c,
            Ok(Command::Derive(Job {
                spec: "s.py".into(),
                out: Some("a.rs".into()),
                name: Some("A".into()),
                tests: true,
                force: false,
                mode: Mode::Write,
            }))
        );
    }

    #[test]
    fn files_to_check_or_update() {
        let c = parse(&strings(&["--check", "a.rs", "b.rs"]));
        assert_eq!(
            c,
            Ok(Command::Files(strings(&["a.rs", "b.rs"]), Mode::Check))
        );
        let c = parse(&strings(&["--update", "a.rs"]));
        assert_eq!(c, Ok(Command::Files(strings(&["a.rs"]), Mode::Write)));
        let c = parse(&strings(&["s.py", "--out", "a.rs", "--check"]));
        assert!(matches!(
            c,
            Ok(Command::Derive(Job {
                mode: Mode::Check,
                ..
            }))
        ));
    }

    #[test]
    fn bad_command_lines() {
        for bad in [
            &["--out"][..],
            &[][..],
            &["a.py", "b.py"][..],
            &["--frobnicate", "a.py"][..],
            &["--update", "--tests", "a.rs"][..],
            &["--update"][..],
        ] {
            assert!(parse(&strings(bad)).is_err(), "{bad:?}");
        }
    }
}
