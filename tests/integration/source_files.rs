//! Every source and test file stays under 800 lines: past that, a file
//! holds more than one concept and is split (issue 34).

use std::path::{Path, PathBuf};

use crate::common;

const MAX_LINES: usize = 800;

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            // Build output of the fuzz crate, not source.
            if path.file_name().is_some_and(|n| n == "target") {
                continue;
            }
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn no_source_or_test_file_exceeds_800_lines() {
    let mut files = Vec::new();
    for dir in ["src", "tests", "benches", "fuzz/fuzz_targets", "fuzz/src"] {
        rust_files(&common::repo_path(dir), &mut files);
    }
    // The walk found the tree (a wrong root would pass vacuously).
    assert!(files.len() > 100, "only {} Rust files found", files.len());
    assert!(files.iter().any(|f| f.ends_with("src/lib.rs")));
    let mut long: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let lines = std::fs::read_to_string(f).ok()?.lines().count();
            (lines > MAX_LINES).then(|| format!("{} ({lines} lines)", f.display()))
        })
        .collect();
    long.sort();
    assert!(long.is_empty(), "files over {MAX_LINES} lines: {long:#?}");
}
