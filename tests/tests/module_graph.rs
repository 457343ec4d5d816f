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
            problems.push(format!(
                "{}: a cycle of modules: {}",
                shown(&repo, std::slice::from_ref(root)),
                modules.join(" → ")
            ));
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

/// The modules a crate root's doc lists in its sentence "Modules, each
/// using only those before it: `a` (…), `b` (…) …", in its order.
fn listed_layers(root_text: &str) -> Vec<String> {
    let doc: Vec<&str> = root_text.lines().filter_map(|l| l.strip_prefix("//!")).map(str::trim).collect();
    let Some(start) = doc.iter().position(|l| l.starts_with("Modules, each using only those before it:")) else {
        return Vec::new();
    };
    let paragraph = doc[start..].iter().take_while(|l| !l.is_empty()).copied().collect::<Vec<_>>().join(" ");
    // A layer is a backticked word outside parentheses.
    let mut layers = Vec::new();
    let (mut depth, mut word, mut in_tick) = (0, String::new(), false);
    for c in paragraph.chars() {
        match c {
            '(' | '[' => depth += 1,
            ')' | ']' => depth -= 1,
            '`' if depth == 0 => {
                if in_tick {
                    layers.push(std::mem::take(&mut word));
                }
                in_tick = !in_tick;
            }
            _ if in_tick => word.push(c),
            _ => {}
        }
    }
    layers
}

#[test]
fn links_layers_are_its_modules_and_each_uses_only_those_before_it() {
    let root = octrace_tests::repo().join("link/src/lib.rs").canonicalize().expect("link's root");
    let text = std::fs::read_to_string(&root).expect("link's root");
    let layers = listed_layers(&text);
    let mut declared: Vec<String> = text
        .lines()
        .map(str::trim)
        .filter_map(|l| l.strip_prefix("pub mod ").or_else(|| l.strip_prefix("mod ")))
        .filter_map(|l| l.strip_suffix(';'))
        .map(String::from)
        .collect();
    let mut sorted = layers.clone();
    sorted.sort();
    declared.sort();
    assert_eq!(sorted, declared, "link's crate doc lists {layers:?}; its modules are {declared:?}");
    let krate = Crate::read(&root).unwrap_or_else(|e| panic!("{e}"));
    // A module and all below it are one layer (sibling edges join them).
    let place = |module: &Vec<String>| layers.iter().position(|l| module.len() == 1 && &module[0] == l);
    let mut wrong = Vec::new();
    for (from, targets) in krate.sibling_edges() {
        for target in targets {
            if let (Some(a), Some(b)) = (place(&from), place(&target)) {
                if b >= a {
                    wrong.push(format!("{} uses {}, listed after it", from.join("::"), target.join("::")));
                }
            }
        }
    }
    assert!(wrong.is_empty(), "link's layers do not hold:\n{}", wrong.join("\n"));
}

#[test]
fn the_layer_list_is_read_from_its_sentence() {
    let text = "//! Intro `x`.\n//!\n//! Modules, each using only those before it: `a` (the\n//! `z` thing, [`T`]), `b`\n//! and `c`.\n//!\n//! `d`\n";
    assert_eq!(listed_layers(text), ["a", "b", "c"]);
}

/// The most lines a Rust file may have before its test module.
const RUST_LINES: usize = 700;
/// The most lines a JavaScript file (`.js`, `.mjs`) may have.
const SCRIPT_LINES: usize = 500;

/// The lines of a Rust file before its test module: the top-level
/// `#[cfg(test)]` whose item is a `mod`, as the house places it at the
/// bottom (a whole file when it has none).
fn lines_before_tests(text: &str) -> usize {
    let lines: Vec<&str> = text.lines().collect();
    let is_test_module = |at: usize| {
        lines[at] == "#[cfg(test)]"
            && lines[at + 1..]
                .iter()
                .find(|l| !l.starts_with("#["))
                .is_some_and(|l| l.starts_with("mod ") || l.starts_with("pub(crate) mod ") || l.starts_with("pub mod "))
    };
    (0..lines.len()).find(|&at| is_test_module(at)).unwrap_or(lines.len())
}

/// Every Rust and JavaScript file of the repository's own (not `target/`,
/// `node_modules/` or `.git`), from the repository's root.
fn source_files(repo: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![repo.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
            let path = entry.expect("an entry").path();
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or_default();
            if path.is_dir() {
                if !matches!(name, "target" | "node_modules" | ".git") {
                    stack.push(path);
                }
            } else if path.extension().is_some_and(|e| e == "rs" || e == "js" || e == "mjs") {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

/// Whether `path` is a package's integration test (a file below a `tests`
/// folder beside its `Cargo.toml`): a file of tests, every line of which
/// counts toward its length.
fn is_integration_test(path: &Path) -> bool {
    let is_package = |manifest: PathBuf| std::fs::read_to_string(manifest).is_ok_and(|t| t.contains("[package]"));
    path.ancestors()
        .any(|dir| dir.file_name().is_some_and(|n| n == "tests") && is_package(dir.with_file_name("Cargo.toml")))
}

#[test]
fn no_rust_file_is_over_700_lines_before_its_tests_and_no_script_over_500() {
    let repo = octrace_tests::repo().canonicalize().expect("the repository");
    let files = source_files(&repo);
    let mut long = Vec::new();
    for path in &files {
        let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let shown = path.strip_prefix(&repo).unwrap_or(path).display();
        if path.extension().is_some_and(|e| e == "rs") {
            // An integration test's file is tests from its first line: all
            // of it counts.
            let lines = if is_integration_test(path) { text.lines().count() } else { lines_before_tests(&text) };
            if lines > RUST_LINES {
                long.push(format!("{shown}: {lines} lines before its tests (at most {RUST_LINES})"));
            }
        } else if text.lines().count() > SCRIPT_LINES {
            long.push(format!("{shown}: {} lines (at most {SCRIPT_LINES})", text.lines().count()));
        }
    }
    assert!(files.len() > 250, "only {} files read", files.len());
    assert!(long.is_empty(), "files to split by concern:\n{}", long.join("\n"));
}

#[test]
fn the_lines_before_tests_end_at_the_test_module() {
    let text = "//! A.\n#[cfg(test)]\nuse x::y;\nfn a() {}\n\n#[cfg(test)]\n#[allow(dead_code)]\nmod tests {\n}\n";
    assert_eq!(lines_before_tests(text), 5);
    assert_eq!(lines_before_tests("fn a() {}\nfn b() {}\n"), 2);
    let repo = octrace_tests::repo().canonicalize().expect("the repository");
    assert!(is_integration_test(&repo.join("tests/tests/golden.rs")));
    assert!(!is_integration_test(&repo.join("tests/src/lib.rs")));
    assert!(!is_integration_test(&repo.join("core/src/math/vector.rs")));
}
