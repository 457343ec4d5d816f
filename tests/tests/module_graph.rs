//! Imports point one way (the house rule): in each crate checked here, no
//! module imports one that imports it back, directly or through others.
//!
//! Read from the sources, not the compiler: a module's file (its test
//! module at the bottom left out, and comments) names other modules as
//! `crate::a::b`, `super::a`, `self::a` or, for its own child, `a::…`. A
//! module using its parent's or a child's items is one unit split into
//! files; what must not loop are the edges between siblings (under the
//! modules they have in common), such as `cli` → `board` → `cli`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// A module: its path from the crate root (empty for the root).
type Module = Vec<String>;

/// Every module of the crate whose sources are in `src` (its `bin/` left
/// out), with its code.
fn modules(src: &Path) -> BTreeMap<Module, String> {
    let mut found = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
            let path = entry.expect("a directory entry").path();
            let relative = path.strip_prefix(src).expect("under src");
            if path.is_dir() {
                if relative != Path::new("bin") {
                    stack.push(path);
                }
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let mut module: Module = relative.iter().map(|p| p.to_string_lossy().into_owned()).collect();
            let file = module.pop().expect("a file name");
            match file.as_str() {
                "lib.rs" | "main.rs" if module.is_empty() => {}
                "mod.rs" => {}
                _ => module.push(file.trim_end_matches(".rs").to_string()),
            }
            let text = std::fs::read_to_string(&path).expect("a source file");
            found.insert(module, code(&text));
        }
    }
    found
}

/// The code of a source file: without its comments and without its test
/// module (at the bottom, as the house rules place it).
fn code(text: &str) -> String {
    let text = text.split("#[cfg(test)]\nmod tests").next().unwrap_or_default();
    text.lines().map(|line| line.split("//").next().unwrap_or_default()).collect::<Vec<_>>().join("\n")
}

/// The modules `module`'s code names.
fn named(module: &Module, code: &str, all: &BTreeMap<Module, String>) -> BTreeSet<Module> {
    let mut names = BTreeSet::new();
    let words: Vec<char> = code.chars().collect();
    let is_word = |c: char| c.is_alphanumeric() || c == '_';
    let mut i = 0;
    while i < words.len() {
        // A path starts at a word that no word or `::` precedes.
        let starts = is_word(words[i]) && (i == 0 || !(is_word(words[i - 1]) || words[i - 1] == ':'));
        if !starts {
            i += 1;
            continue;
        }
        let mut segments = Vec::new();
        let mut j = i;
        loop {
            let start = j;
            while j < words.len() && is_word(words[j]) {
                j += 1;
            }
            segments.push(words[start..j].iter().collect::<String>());
            if j + 2 < words.len() && words[j] == ':' && words[j + 1] == ':' && is_word(words[j + 2]) {
                j += 2;
            } else {
                break;
            }
        }
        // `use a::{b, c::d}`: each member continues the path.
        let mut paths = vec![segments.clone()];
        if j + 2 < words.len() && words[j] == ':' && words[j + 1] == ':' && words[j + 2] == '{' {
            let close = words[j + 3..].iter().position(|&c| c == '}').map_or(words.len(), |p| j + 3 + p);
            let group: String = words[j + 3..close].iter().collect();
            for member in group.split(',') {
                let mut path = segments.clone();
                path.extend(member.trim().split("::").filter(|s| !s.is_empty()).map(str::to_string));
                paths.push(path);
            }
        }
        for path in paths {
            // Where the path starts, and how many of its segments that took.
            let (mut base, skip): (Module, usize) = match path[0].as_str() {
                "crate" => (Vec::new(), 1),
                "self" => (module.clone(), 1),
                "super" => {
                    let ups = path.iter().take_while(|s| *s == "super").count();
                    (module[..module.len().saturating_sub(ups)].to_vec(), ups)
                }
                // A child of this module named by its own name, or no module.
                _ => (module.clone(), 0),
            };
            for segment in &path[skip..] {
                let mut deeper = base.clone();
                deeper.push(segment.clone());
                if !all.contains_key(&deeper) {
                    break;
                }
                base = deeper;
            }
            if skip > 0 || base.len() > module.len() {
                names.insert(base);
            }
        }
        i = j;
    }
    names
}

/// The import edges between siblings: for an edge from `a` to `b`, the
/// children of their common ancestor on each side (none when one is the
/// other's ancestor).
fn sibling_edges(all: &BTreeMap<Module, String>) -> BTreeMap<Module, BTreeSet<Module>> {
    let mut edges: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    for (module, code) in all {
        for target in named(module, code, all) {
            let common = module.iter().zip(&target).take_while(|(a, b)| a == b).count();
            if common == module.len() || common == target.len() {
                continue;
            }
            edges.entry(module[..=common].to_vec()).or_default().insert(target[..=common].to_vec());
        }
    }
    edges
}

/// A cycle among `edges`, if there is one, as the modules along it.
fn cycle(edges: &BTreeMap<Module, BTreeSet<Module>>) -> Option<Vec<Module>> {
    fn visit(
        module: &Module,
        edges: &BTreeMap<Module, BTreeSet<Module>>,
        path: &mut Vec<Module>,
        done: &mut BTreeSet<Module>,
    ) -> Option<Vec<Module>> {
        if let Some(at) = path.iter().position(|m| m == module) {
            let mut found = path[at..].to_vec();
            found.push(module.clone());
            return Some(found);
        }
        if done.contains(module) {
            return None;
        }
        path.push(module.clone());
        for next in edges.get(module).into_iter().flatten() {
            if let Some(found) = visit(next, edges, path, done) {
                return Some(found);
            }
        }
        path.pop();
        done.insert(module.clone());
        None
    }
    let mut done = BTreeSet::new();
    edges.keys().find_map(|start| visit(start, edges, &mut Vec::new(), &mut done))
}

fn shown(cycle: &[Module]) -> String {
    cycle.iter().map(|m| if m.is_empty() { "crate".into() } else { m.join("::") }).collect::<Vec<_>>().join(" → ")
}

/// The crates checked: host-sim (whose `board` and `cli` once imported
/// each other) and those whose layers docs/architecture.md lists.
const CRATES: [&str; 4] = ["host-sim", "core", "link", "images"];

#[test]
fn no_module_imports_one_that_imports_it_back() {
    for name in CRATES {
        let src = octrace_tests::repo().join(name).join("src");
        let all = modules(&src);
        assert!(all.len() > 3, "{name}: only {} modules found in {}", all.len(), src.display());
        let edges = sibling_edges(&all);
        if let Some(found) = cycle(&edges) {
            panic!("{name}: a module cycle: {}", shown(&found));
        }
    }
}

#[test]
fn the_check_sees_a_cycle_through_a_grouped_use_and_a_super_path() {
    let all: BTreeMap<Module, String> = [
        (vec![], "mod a; mod b; mod c;".to_string()),
        (vec!["a".to_string()], "use crate::{b::thing, other};".to_string()),
        (vec!["b".to_string()], "use crate::c::Item;".to_string()),
        (vec!["c".to_string()], "mod d;".to_string()),
        (vec!["c".to_string(), "d".to_string()], "fn f() { super::super::a::call() }".to_string()),
    ]
    .into_iter()
    .collect();
    let found = cycle(&sibling_edges(&all)).expect("a → b → c → a");
    assert_eq!(shown(&found), "a → b → c → a");
    // A module using its parent's items, and the parent its child's, is no cycle.
    let nested: BTreeMap<Module, String> = [
        (vec![], "mod a; use a::f;".to_string()),
        (vec!["a".to_string()], "use crate::Item; use super::Other;".to_string()),
    ]
    .into_iter()
    .collect();
    assert_eq!(cycle(&sibling_edges(&nested)), None);
}
