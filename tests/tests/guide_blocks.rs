//! Every code block of README.md and the guide is either Rust that the doc tests compile and
//! run, or another language named on its fence: a block with no language (which rustdoc
//! would take for Rust and mdBook would not), a Rust block marked `ignore` or `no_run`, or a
//! chapter that the doc tests do not include would let an example rot unseen.

use std::path::{Path, PathBuf};

/// The languages a block may have besides Rust; none of them is compiled.
const OTHER_LANGUAGES: [&str; 5] = ["sh", "text", "toml", "python", "js"];

/// Attributes that would keep rustdoc from running a Rust block.
const SKIPPING: [&str; 3] = ["ignore", "no_run", "compile_fail"];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The info string of every fenced block of `text` (the opening fences only).
fn fences(text: &str) -> Vec<String> {
    let mut open = false;
    let mut infos = Vec::new();
    for line in text.lines() {
        if let Some(info) = line.trim_start().strip_prefix("```") {
            if !open {
                infos.push(info.trim().to_string());
            }
            open = !open;
        }
    }
    assert!(!open, "a fence is not closed");
    infos
}

/// Counts the Rust blocks of `file`, failing on a block that would not be run.
fn rust_blocks(file: &Path) -> Result<usize, String> {
    let text = std::fs::read_to_string(file).map_err(|e| format!("{}: {e}", file.display()))?;
    let mut count = 0;
    for info in fences(&text) {
        let mut words = info.split(',').map(str::trim);
        let language = words.next().unwrap_or_default();
        if language == "rust" {
            if let Some(skip) = words.find(|w| SKIPPING.contains(w)) {
                return Err(format!(
                    "{}: a Rust block is marked `{skip}`",
                    file.display()
                ));
            }
            count += 1;
        } else if !OTHER_LANGUAGES.contains(&language) {
            return Err(format!(
                "{}: a block's fence says `{info}`: name its language (rust, or one of {OTHER_LANGUAGES:?})",
                file.display()
            ));
        }
    }
    Ok(count)
}

#[test]
fn every_block_is_run_or_named() -> Result<(), String> {
    let guide = root().join("guide/src");
    let mut chapters: Vec<String> = std::fs::read_dir(&guide)
        .map_err(|e| e.to_string())?
        .filter_map(|entry| entry.ok())
        .map(|entry| entry.file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".md") && name != "SUMMARY.md")
        .collect();
    chapters.sort();
    let mut total = rust_blocks(&root().join("README.md"))?;
    assert!(
        total >= 1,
        "README.md has no Rust block: its quick start is gone"
    );
    for chapter in &chapters {
        let blocks = rust_blocks(&guide.join(chapter))?;
        if blocks > 0 && !lagrange_tests::GUIDE_CHAPTERS.contains(&chapter.as_str()) {
            return Err(format!(
                "guide/src/{chapter} has {blocks} Rust blocks that no doc test runs: add it to chapters! in tests/src/lib.rs"
            ));
        }
        total += blocks;
    }
    for included in lagrange_tests::GUIDE_CHAPTERS {
        assert!(
            chapters.iter().any(|c| c == included),
            "{included} is not in guide/src"
        );
    }
    println!(
        "{total} Rust blocks in README.md and {} chapters, each run as a doc test",
        chapters.len()
    );
    assert!(
        total >= 10,
        "{total} Rust blocks: fewer than the guide had when this test was written"
    );
    Ok(())
}

#[test]
fn a_skipped_or_unnamed_block_is_refused() -> std::io::Result<()> {
    let dir = std::env::temp_dir().join(format!("guide-blocks-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    for (text, refused) in [
        ("```rust\nlet x = 1;\n```\n", false),
        ("```rust,ignore\nlet x = 1;\n```\n", true),
        ("```rust,no_run\nlet x = 1;\n```\n", true),
        ("```\nlet x = 1;\n```\n", true),
        ("```sh\ncargo run\n```\n", false),
    ] {
        let file = dir.join("chapter.md");
        std::fs::write(&file, text)?;
        assert_eq!(rust_blocks(&file).is_err(), refused, "{text}");
    }
    std::fs::remove_dir_all(&dir)
}
