//! Tidy checks that run as tests (after rust-analyzer's `xtask/src/tidy.rs`): every Rust file
//! has a module doc, the flight code has no placeholders, and the README names only commands
//! the xtask has.

use crate::shell::workspace_root;
use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if path.is_dir() {
            if name != "target" && !name.starts_with('.') {
                rust_files(&path, out);
            }
        } else if name.ends_with(".rs") {
            out.push(path);
        }
    }
}

fn all_rust_files() -> Vec<PathBuf> {
    let mut files = Vec::new();
    rust_files(&workspace_root(), &mut files);
    files
}

#[test]
fn every_rust_file_starts_with_a_module_doc() {
    let mut missing = Vec::new();
    for file in all_rust_files() {
        let text = std::fs::read_to_string(&file).unwrap_or_default();
        let first = text.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
        if !first.starts_with("//!") {
            missing.push(file.display().to_string());
        }
    }
    assert!(
        missing.is_empty(),
        "files without a `//!` module doc: {missing:#?}"
    );
}

#[test]
fn flight_code_has_no_placeholders() {
    let mut src = Vec::new();
    rust_files(&workspace_root().join("src"), &mut src);
    assert!(!src.is_empty());
    let banned = ["todo!(", "unimplemented!(", "dbg!("];
    let mut hits = Vec::new();
    for file in src {
        let text = std::fs::read_to_string(&file).unwrap_or_default();
        for (n, line) in text.lines().enumerate() {
            if banned.iter().any(|b| line.contains(b)) {
                hits.push(format!("{}:{}: {}", file.display(), n + 1, line.trim()));
            }
        }
    }
    assert!(hits.is_empty(), "placeholders in src/: {hits:#?}");
}

#[test]
fn readme_commands_exist_in_the_xtask() {
    let readme = std::fs::read_to_string(workspace_root().join("README.md")).unwrap_or_default();
    let used: Vec<&str> = readme
        .split("cargo xtask ")
        .skip(1)
        .filter_map(|rest| {
            rest.split(|c: char| !c.is_ascii_alphanumeric() && c != '-')
                .next()
        })
        .filter(|word| !word.is_empty())
        .collect();
    assert!(
        used.contains(&"run") && used.contains(&"test"),
        "README must give `cargo xtask run` and `cargo xtask test`"
    );
    for word in used {
        assert!(
            crate::command_names().iter().any(|name| name == word),
            "README names `cargo xtask {word}`, which the xtask does not have"
        );
    }
}

#[test]
fn ci_runs_the_readme_test_command() {
    let ci = std::fs::read_to_string(workspace_root().join(".ci/run")).unwrap_or_default();
    assert!(
        ci.lines().any(|l| l.trim() == "cargo xtask test"),
        ".ci/run must run `cargo xtask test`"
    );
}

#[test]
fn docs_name_only_commands_the_xtask_has() {
    let mut pages = Vec::new();
    let docs = workspace_root().join("docs");
    for dir in [docs.clone(), docs.join("results")] {
        for entry in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
            if entry.path().extension().is_some_and(|e| e == "md") {
                pages.push(entry.path());
            }
        }
    }
    assert!(!pages.is_empty());
    for page in pages {
        let text = std::fs::read_to_string(&page).unwrap_or_default();
        for rest in text.split("cargo xtask ").skip(1) {
            let word = rest
                .split(|c: char| !c.is_ascii_alphanumeric() && c != '-')
                .next()
                .unwrap_or("");
            assert!(
                word.is_empty() || crate::command_names().iter().any(|name| name == word),
                "{} names `cargo xtask {word}`, which the xtask does not have",
                page.display()
            );
        }
    }
}
