//! Support code for octrace's whole-pipeline tests (the tests themselves are
//! in `tests/`).

pub mod reference;

use std::path::PathBuf;

/// The repository root.
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Every scene file in `scenes/`, sorted by name: (name, path).
pub fn scenes() -> Vec<(String, PathBuf)> {
    let mut v: Vec<(String, PathBuf)> = std::fs::read_dir(repo().join("scenes"))
        .expect("scenes/ exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "txt"))
        .map(|p| (p.file_stem().unwrap_or_default().to_string_lossy().into_owned(), p))
        .collect();
    v.sort();
    v
}

/// Whether the tests should rewrite their expected files (`OCTRACE_BLESS=1`).
pub fn blessing() -> bool {
    std::env::var_os("OCTRACE_BLESS").is_some_and(|v| v != "0")
}
