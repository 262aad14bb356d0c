//! `cargo xtask guide`: the user's guide (`guide/`, mdBook) built into `target/guide/`, with
//! no warning and no broken link (every relative link and anchor of the built pages, and of
//! README.md, checked offline), and `--figures`: its plots made again by the examples and the
//! bench, and the page's screenshot by `web --test`, copied into `guide/src/figures/`.
//!
//! The Rust blocks of the guide and the README are compiled and run as doc tests of
//! `lagrange-tests` (`cargo xtask test`); `tests/tests/guide_blocks.rs` fails on one that
//! would be skipped.

use std::path::{Path, PathBuf};

use crate::cmd;
use crate::tools::CargoTool;

/// mdBook, pinned. Without its default features (`serve` and `watch`: a web server and a file
/// watcher that a build does not use) it installs in a fraction of the time; unoptimised,
/// as the book is small.
pub(crate) const MDBOOK: CargoTool = CargoTool {
    name: "mdbook",
    version: "0.5.4",
    install_args: &["--debug", "--no-default-features", "--features", "search"],
};

/// Where the book's sources are, from the project root.
const SOURCE: &str = "guide";

/// Where it is built, from the project root.
const OUT: &str = "target/guide";

/// A figure of the guide: the file a command writes, and its name under `guide/src/figures`.
struct Figure {
    /// The command, as `cargo` arguments.
    command: &'static [&'static str],
    /// The file it writes, from the project root (a `*` matches any run of characters).
    made: &'static str,
    /// Its name in the guide.
    name: &'static str,
}

const FIGURES: [Figure; 4] = [
    Figure {
        command: &[
            "run",
            "--release",
            "--quiet",
            "--example",
            "origin_pendulum",
        ],
        made: "target/lagrange-demo/pendulum.svg",
        name: "pendulum.svg",
    },
    Figure {
        command: &["run", "--release", "--quiet", "--example", "four_bar"],
        made: "target/lagrange-demo/constraints.svg",
        name: "constraints.svg",
    },
    Figure {
        command: &["xtask", "bench", "--only", "P1"],
        made: "target/lagrange-bench/wp-P1*f64-error.svg",
        name: "work-precision-p1.svg",
    },
    Figure {
        command: &["xtask", "web", "--test"],
        made: "target/lagrange-web/screenshot.png",
        name: "page.png",
    },
];

/// `cargo xtask guide [--figures]`.
pub fn run(args: &[String]) -> Result<(), String> {
    if args.iter().any(|a| a == "--figures") {
        figures()?;
    }
    build()?;
    let root = cmd::project_root();
    let (checked, external) = check_links(&root.join(OUT))?;
    let readme = check_readme(&root)?;
    println!(
        "xtask guide: {} ({checked} links and anchors checked, {readme} in README.md; {external} \
         external links not followed, offline)",
        root.join(OUT).join("index.html").display()
    );
    Ok(())
}

/// Makes each figure again and copies it into the guide.
fn figures() -> Result<(), String> {
    let root = cmd::project_root();
    for figure in &FIGURES {
        cmd::run(cmd::cargo().current_dir(&root).args(figure.command))?;
        let made = matching(&root, figure.made)?;
        let to = root.join(SOURCE).join("src/figures").join(figure.name);
        std::fs::copy(&made, &to)
            .map_err(|e| format!("{} -> {}: {e}", made.display(), to.display()))?;
        println!("guide figure {}: from {}", figure.name, made.display());
    }
    Ok(())
}

/// The one file that `pattern` (a path with at most one `*` in its file name) names.
fn matching(root: &Path, pattern: &str) -> Result<PathBuf, String> {
    let path = root.join(pattern);
    let Some((head, tail)) = pattern
        .rsplit_once('/')
        .and_then(|(_, name)| name.split_once('*'))
    else {
        return Ok(path);
    };
    let dir = path.parent().ok_or("a pattern without a folder")?;
    let found: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(Result::ok)
        .map(|entry| entry.path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with(head) && n.ends_with(tail))
        })
        .collect();
    match found.as_slice() {
        [one] => Ok(one.clone()),
        _ => Err(format!("{pattern}: {} files match, not one", found.len())),
    }
}

/// Builds the book; a warning or an error in mdBook's log fails the build.
fn build() -> Result<(), String> {
    let mdbook = MDBOOK.ensure()?;
    let root = cmd::project_root();
    let output = std::process::Command::new(&mdbook)
        .current_dir(&root)
        .args(["build", SOURCE, "--dest-dir"])
        .arg(root.join(OUT))
        .output()
        .map_err(|e| format!("{}: {e}", mdbook.display()))?;
    let log = String::from_utf8_lossy(&output.stderr).into_owned()
        + &String::from_utf8_lossy(&output.stdout);
    print!("{log}");
    if !output.status.success() {
        return Err(format!("mdbook build failed ({})", output.status));
    }
    let complaints: Vec<&str> = log
        .lines()
        .filter(|l| l.contains("WARN") || l.contains("ERROR"))
        .collect();
    if complaints.is_empty() {
        Ok(())
    } else {
        Err(format!("mdbook warned:\n{}", complaints.join("\n")))
    }
}

/// The links of a page: the values of its `href` and `src` attributes.
fn links(html: &str) -> Vec<&str> {
    let mut found = Vec::new();
    for attribute in ["href=\"", "src=\""] {
        let mut rest = html;
        while let Some(start) = rest.find(attribute) {
            rest = &rest[start + attribute.len()..];
            if let Some(end) = rest.find('"') {
                found.push(&rest[..end]);
                rest = &rest[end..];
            }
        }
    }
    found
}

/// Whether `link` leaves the book (followed by nobody here: the check is offline).
fn is_external(link: &str) -> bool {
    ["http://", "https://", "mailto:", "javascript:", "data:"]
        .iter()
        .any(|scheme| link.starts_with(scheme))
}

/// Checks that every relative link of every built page names a file that exists and, with a
/// `#fragment`, an element of that id in it; the counts of links checked and not followed.
fn check_links(out: &Path) -> Result<(usize, usize), String> {
    let mut pages = Vec::new();
    html_files(out, &mut pages)?;
    let (mut checked, mut external) = (0, 0);
    let mut broken = Vec::new();
    for page in &pages {
        let html = std::fs::read_to_string(page).map_err(|e| format!("{}: {e}", page.display()))?;
        for link in links(&html) {
            if is_external(link) {
                external += 1;
                continue;
            }
            checked += 1;
            let (path, fragment) = link.split_once('#').unwrap_or((link, ""));
            let path = path.split('?').next().unwrap_or_default();
            let target = if path.is_empty() {
                page.clone()
            } else {
                // A path from the site's root (mdBook's 404 page) is from the book's.
                let base = if path.starts_with('/') {
                    out
                } else {
                    page.parent().unwrap_or(out)
                };
                let joined = base.join(path.trim_start_matches('/'));
                if path.ends_with('/') {
                    joined.join("index.html")
                } else {
                    joined
                }
            };
            if !target.is_file() {
                broken.push(format!("{}: {link} (no such file)", page.display()));
            } else if !fragment.is_empty() && target.extension().is_some_and(|e| e == "html") {
                let text = std::fs::read_to_string(&target).unwrap_or_default();
                if !text.contains(&format!("id=\"{fragment}\"")) {
                    broken.push(format!("{}: {link} (no such anchor)", page.display()));
                }
            }
        }
    }
    if broken.is_empty() {
        Ok((checked, external))
    } else {
        Err(format!("broken links in the guide:\n{}", broken.join("\n")))
    }
}

/// The HTML files under `dir`, recursively.
fn html_files(dir: &Path, out: &mut Vec<PathBuf>) -> Result<(), String> {
    for entry in std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))? {
        let path = entry.map_err(|e| e.to_string())?.path();
        if path.is_dir() {
            html_files(&path, out)?;
        } else if path.extension().is_some_and(|e| e == "html") {
            out.push(path);
        }
    }
    Ok(())
}

/// Checks README.md's relative Markdown links (`](path)`): each names a file or folder of
/// the repository. The count checked.
fn check_readme(root: &Path) -> Result<usize, String> {
    let text = std::fs::read_to_string(root.join("README.md")).map_err(|e| e.to_string())?;
    let mut checked = 0;
    let mut broken = Vec::new();
    let mut rest = text.as_str();
    while let Some(start) = rest.find("](") {
        rest = &rest[start + 2..];
        let Some(end) = rest.find(')') else { break };
        let link = &rest[..end];
        if !is_external(link) && !link.starts_with('#') {
            checked += 1;
            let path = link.split('#').next().unwrap_or_default();
            if !root.join(path).exists() {
                broken.push(link.to_string());
            }
        }
    }
    if broken.is_empty() {
        Ok(checked)
    } else {
        Err(format!("broken links in README.md: {}", broken.join(", ")))
    }
}

#[cfg(test)]
mod tests {
    use super::{is_external, links};

    #[test]
    fn links_are_read_from_both_attributes() {
        let html = r#"<a href="a.html#x">a</a><img src="figures/p.svg"><a href="https://e.org">"#;
        assert_eq!(links(html), ["a.html#x", "https://e.org", "figures/p.svg"]);
        assert!(is_external("https://e.org") && !is_external("a.html#x"));
    }
}
