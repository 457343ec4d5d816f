//! Imports point one way (the house rule): in every crate of the
//! repository, no file uses an item of a file that uses one of its own,
//! directly or through others; and no module is placed with `#[path]`.
//!
//! The graph is the files' (`octrace_tests::imports`): a name re-exported
//! at a crate root leads to the file that defines it, and a module's
//! `mod.rs` is a file like any other, so a parent that uses its child while
//! the child uses the parent's items is a cycle too.

use octrace_tests::imports::{cycles, Crate};
use std::path::{Path, PathBuf};

/// Every crate root in the repository: each package's library, binaries,
/// build script and integration tests, and the fuzz targets.
fn roots() -> Vec<PathBuf> {
    let repo = octrace_tests::repo();
    let mut packages = vec![repo.clone(), repo.join("fuzz")];
    for folder in ["examples"] {
        for entry in std::fs::read_dir(repo.join(folder)).expect("examples/") {
            packages.push(entry.expect("an entry").path());
        }
    }
    for entry in std::fs::read_dir(&repo).expect("the repository") {
        let path = entry.expect("an entry").path();
        if path.join("Cargo.toml").exists() {
            packages.push(path);
        }
    }
    let mut roots = Vec::new();
    for package in packages {
        if !package.join("Cargo.toml").exists() {
            continue;
        }
        for name in ["src/lib.rs", "src/main.rs", "build.rs"] {
            let root = package.join(name);
            if root.exists() {
                roots.push(root);
            }
        }
        for folder in ["src/bin", "tests", "fuzz_targets"] {
            let Ok(entries) = std::fs::read_dir(package.join(folder)) else { continue };
            for entry in entries {
                let path = entry.expect("an entry").path();
                if path.extension().is_some_and(|e| e == "rs") {
                    roots.push(path);
                } else if path.join("main.rs").exists() {
                    roots.push(path.join("main.rs"));
                }
            }
        }
    }
    roots.sort();
    roots.dedup();
    roots
}

fn shown(repo: &Path, cycle: &[PathBuf]) -> String {
    let short = |p: &PathBuf| p.strip_prefix(repo).unwrap_or(p).display().to_string();
    cycle.iter().map(short).collect::<Vec<_>>().join(" → ")
}

#[test]
fn no_file_imports_one_that_imports_it_back_in_any_crate() {
    let repo = octrace_tests::repo().canonicalize().expect("the repository");
    let roots = roots();
    let mut read = 0;
    let mut problems = Vec::new();
    for root in &roots {
        let krate = Crate::read(&root.canonicalize().expect("a root")).unwrap_or_else(|e| panic!("{e}"));
        read += krate.len();
        for found in cycles(&krate.file_edges()) {
            let why: Vec<String> = found
                .windows(2)
                .map(|pair| {
                    format!(
                        "    {} uses {}",
                        shown(&repo, &pair[..1]),
                        krate.uses_between(&pair[0], &pair[1]).join(", ")
                    )
                })
                .collect();
            problems.push(format!("a cycle of files: {}\n{}", shown(&repo, &found), why.join("\n")));
        }
        for found in cycles(&krate.sibling_edges()) {
            let modules: Vec<_> =
                found.iter().map(|m| if m.is_empty() { "crate".into() } else { m.join("::") }).collect();
            problems.push(format!("{}: a cycle of modules: {}", shown(&repo, &[root.clone()]), modules.join(" → ")));
        }
        for file in krate.path_attributes() {
            problems.push(format!("{}: a #[path] attribute", shown(&repo, &[file])));
        }
    }
    // Every package the workspace and the boards have, and their modules.
    for package in
        ["core", "host-sim", "link", "images", "studio", "pico", "pico-build", "firmware", "examples/pico-st7789"]
    {
        assert!(roots.iter().any(|r| r.starts_with(octrace_tests::repo().join(package))), "{package} is not checked");
    }
    assert!(read > 150, "only {read} modules read");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
