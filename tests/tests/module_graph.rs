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
