//! The import graph of a crate's files, read from its sources: which file
//! uses an item that another file defines. The house rule it serves is that
//! imports point one way (tests/tests/module_graph.rs).
//!
//! A crate is read from its root (`lib.rs`, `main.rs` or a binary's file) by
//! following its `mod NAME;` declarations, so a file no root declares is no
//! part of it. Each file's code is tokenized (comments, strings and
//! characters dropped; the test module at the bottom, as the house rules
//! place it, left out). Then:
//!
//! - a file *defines* the items it declares (`fn`, `struct`, `enum`,
//!   `trait`, `type`, `const`, `static`, `union`, `macro_rules!`) and *binds*
//!   the names its `use` declarations bring in;
//! - a re-export (a `use` with a visibility, `pub use …`) is the module's
//!   interface, not a use: it is no edge, and a path through it reaches the
//!   file that defines the item (the crate root that re-exports a module's
//!   type is not where that type comes from);
//! - every other `use` and every path in the code (`crate::a::B`,
//!   `super::f`, `self::x`, `a::B` through a name in scope) is an edge from
//!   its file to the file that defines what it names; an item reached
//!   through a glob (`use super::*`) counts as the glob's module's.
//!
//! What this cannot see: a name a macro makes (a path through it ends at
//! the module the macro is invoked in, the conservative guess), and a
//! method call (methods are not imported).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A module: its path from the crate root (empty for the root).
pub type Module = Vec<String>;

/// A crate's modules, each with its file and what it defines and binds.
#[derive(Debug, Default)]
pub struct Crate {
    modules: BTreeMap<Module, Unit>,
    /// Every `macro_rules!` by name: `#[macro_export]` puts them at the
    /// root, where a `crate::name!` path looks for them.
    macros: BTreeMap<String, Module>,
}

#[derive(Debug, Default)]
struct Unit {
    file: PathBuf,
    tokens: Vec<Token>,
    children: BTreeSet<String>,
    defined: BTreeSet<String>,
    /// Names brought in by `use`: the path as written, and whether it is a
    /// re-export.
    bound: BTreeMap<String, (Vec<String>, bool)>,
    /// Paths of `use …::*`.
    globs: Vec<Vec<String>>,
    /// The paths this file uses (not its re-exports).
    uses: Vec<Vec<String>>,
    /// `#[path]` attributes found (the house rules have none).
    path_attributes: usize,
}

/// A token of Rust code, as far as paths need: a word, `::`, or any other
/// character.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Token {
    Word(String),
    PathSeparator,
    Punct(char),
}

impl Crate {
    /// Reads the crate whose root file is `root`.
    pub fn read(root: &Path) -> Result<Crate, String> {
        let mut krate = Crate::default();
        let mut pending = vec![(Module::new(), root.to_path_buf())];
        while let Some((module, file)) = pending.pop() {
            let text = std::fs::read_to_string(&file).map_err(|e| format!("{}: {e}", file.display()))?;
            let unit = Unit::read(file.clone(), &text);
            // A child of `a/mod.rs`, `lib.rs` or `main.rs` is beside it; a
            // child of `a/b.rs` is in `a/b/`.
            let dir = match file.file_name().and_then(|n| n.to_str()) {
                Some("mod.rs" | "lib.rs" | "main.rs") => file.parent().unwrap_or(Path::new(".")).to_path_buf(),
                _ if module.is_empty() => file.parent().unwrap_or(Path::new(".")).to_path_buf(),
                _ => file.with_extension(""),
            };
            for child in &unit.children {
                let flat = dir.join(format!("{child}.rs"));
                let nested = dir.join(child).join("mod.rs");
                let found = if flat.exists() { flat } else { nested };
                if !found.exists() {
                    return Err(format!("{}: `mod {child};` has no file", file.display()));
                }
                let mut path = module.clone();
                path.push(child.clone());
                pending.push((path, found));
            }
            for (i, token) in unit.tokens.iter().enumerate() {
                if token == &Token::Word("macro_rules".into()) {
                    if let Some(Token::Word(name)) = unit.tokens.get(i + 2) {
                        krate.macros.entry(name.clone()).or_insert_with(|| module.clone());
                    }
                }
            }
            krate.modules.insert(module, unit);
        }
        Ok(krate)
    }

    /// The number of modules read.
    pub fn len(&self) -> usize {
        self.modules.len()
    }

    /// Whether no module was read.
    pub fn is_empty(&self) -> bool {
        self.modules.is_empty()
    }

    /// The files with a `#[path]` attribute.
    pub fn path_attributes(&self) -> Vec<PathBuf> {
        self.modules.values().filter(|u| u.path_attributes > 0).map(|u| u.file.clone()).collect()
    }

    /// The import edges between modules: for each module, the modules
    /// whose files define what its file uses (a glob import of a module of
    /// this crate uses all of it).
    pub fn edges(&self) -> BTreeMap<Module, BTreeSet<Module>> {
        let mut edges: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
        for (module, unit) in &self.modules {
            let targets = edges.entry(module.clone()).or_default();
            for path in &unit.uses {
                let owner = match self.resolve(module, path) {
                    Some(Found::Item(owner)) => owner,
                    Some(Found::Module(owner)) if unit.globs.contains(path) => owner,
                    _ => continue,
                };
                if &owner != module {
                    targets.insert(owner);
                }
            }
        }
        edges
    }

    /// The paths by which the file `from` uses the file `to`, written as in
    /// `from`: what a message about an edge shows.
    pub fn uses_between(&self, from: &Path, to: &Path) -> Vec<String> {
        let Some((module, unit)) = self.modules.iter().find(|(_, u)| u.file == from) else { return Vec::new() };
        let mut found: Vec<String> = unit
            .uses
            .iter()
            .filter(|path| match self.resolve(module, path) {
                Some(Found::Item(owner) | Found::Module(owner)) => self.modules[&owner].file == to,
                None => false,
            })
            .map(|path| path.join("::"))
            .collect();
        found.sort();
        found.dedup();
        found
    }

    /// [`Crate::edges`] between files.
    pub fn file_edges(&self) -> BTreeMap<PathBuf, BTreeSet<PathBuf>> {
        let file = |m: &Module| self.modules[m].file.clone();
        self.edges().iter().map(|(from, to)| (file(from), to.iter().map(file).collect())).collect()
    }

    /// [`Crate::edges`] between siblings: for an edge from `a` to `b`, the
    /// children of their common ancestor on each side (none when one is the
    /// other's ancestor). A module and all below it are then one node, so
    /// `a` using `b/c.rs` while `b/d.rs` uses `a` is a cycle.
    pub fn sibling_edges(&self) -> BTreeMap<Module, BTreeSet<Module>> {
        let mut edges: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
        for (module, targets) in self.edges() {
            for target in targets {
                let common = module.iter().zip(&target).take_while(|(a, b)| a == b).count();
                if common == module.len() || common == target.len() {
                    continue;
                }
                edges.entry(module[..=common].to_vec()).or_default().insert(target[..=common].to_vec());
            }
        }
        edges
    }

    /// Where `path`, written in `module`, leads: the module that defines
    /// the item it names, or a module, or nothing of this crate.
    fn resolve(&self, module: &Module, path: &[String]) -> Option<Found> {
        self.resolve_once(module, path, &mut BTreeSet::new())
    }

    /// [`Crate::resolve`], each (module, path) tried once: bindings and
    /// globs can lead around in circles.
    fn resolve_once(
        &self,
        module: &Module,
        path: &[String],
        tried: &mut BTreeSet<(Module, Vec<String>)>,
    ) -> Option<Found> {
        // Bindings that lead in circles make ever longer paths: a real
        // path is short.
        if path.is_empty() || path.len() > 24 || tried.len() > 256 || !tried.insert((module.clone(), path.to_vec())) {
            return None;
        }
        let (mut at, rest) = match path[0].as_str() {
            "crate" | "$crate" => (Module::new(), &path[1..]),
            "self" => (module.clone(), &path[1..]),
            "super" => {
                let ups = path.iter().take_while(|s| *s == "super").count();
                (module[..module.len().checked_sub(ups)?].to_vec(), &path[ups..])
            }
            // A name in scope here, or nothing of this crate (another
            // crate, the prelude, a local).
            _ => (module.clone(), path),
        };
        let relative = !matches!(path[0].as_str(), "crate" | "$crate" | "self" | "super");
        for (i, segment) in rest.iter().enumerate() {
            let unit = self.modules.get(&at)?;
            if unit.children.contains(segment) {
                at.push(segment.clone());
                continue;
            }
            if unit.defined.contains(segment) {
                return Some(Found::Item(at));
            }
            if let Some((target, _)) = unit.bound.get(segment) {
                let mut whole = target.clone();
                whole.extend(rest[i + 1..].iter().cloned());
                return self.resolve_once(&at, &whole, tried);
            }
            if at.is_empty() {
                if let Some(owner) = self.macros.get(segment) {
                    return Some(Found::Item(owner.clone()));
                }
            }
            for glob in &unit.globs {
                let mut whole = glob.clone();
                whole.extend(rest[i..].iter().cloned());
                if let Some(found) = self.resolve_once(&at, &whole, tried) {
                    return Some(found);
                }
            }
            // A relative path's first name that is nothing here is another
            // crate's, the prelude's or a local's.
            if relative && i == 0 {
                return None;
            }
            // Made by a macro, or an associated item: the conservative
            // guess is the module reached.
            return Some(Found::Item(at));
        }
        Some(Found::Module(at))
    }
}

/// What a path leads to.
#[derive(Debug, PartialEq, Eq)]
enum Found {
    /// An item defined in this module's file.
    Item(Module),
    /// A module itself.
    Module(Module),
}

impl Unit {
    fn read(file: PathBuf, text: &str) -> Unit {
        let code = text.split("#[cfg(test)]\nmod tests").next().unwrap_or_default();
        let tokens = tokenize(code);
        let mut unit = Unit { file, ..Unit::default() };
        let word = |i: usize| match tokens.get(i) {
            Some(Token::Word(w)) => Some(w.as_str()),
            _ => None,
        };
        let mut i = 0;
        while i < tokens.len() {
            match word(i) {
                Some("mod") if matches!(tokens.get(i + 2), Some(Token::Punct(';'))) => {
                    if let Some(name) = word(i + 1) {
                        unit.children.insert(name.to_string());
                    }
                }
                Some("fn" | "struct" | "enum" | "trait" | "type" | "static" | "union") => {
                    if let Some(name) = word(i + 1) {
                        unit.defined.insert(name.to_string());
                    }
                }
                Some("const") if word(i + 1) != Some("fn") => {
                    if let Some(name) = word(i + 1).filter(|n| *n != "_") {
                        unit.defined.insert(name.to_string());
                    }
                }
                Some("macro_rules") => {
                    if let Some(name) = word(i + 2) {
                        unit.defined.insert(name.to_string());
                    }
                }
                Some("path") if i >= 2 && tokens[i - 1] == Token::Punct('[') && tokens[i - 2] == Token::Punct('#') => {
                    unit.path_attributes += 1;
                }
                Some("use") => {
                    // `pub use`, `pub(crate) use`, `pub(super) use`.
                    let exported = i >= 1
                        && (word(i - 1) == Some("pub")
                            || (tokens[i - 1] == Token::Punct(')') && i >= 4 && word(i - 4) == Some("pub")));
                    let end = tokens[i..].iter().position(|t| t == &Token::Punct(';')).map_or(tokens.len(), |p| i + p);
                    let mut leaves = Vec::new();
                    use_tree(&tokens[i + 1..end], Vec::new(), &mut leaves);
                    for (path, name) in leaves {
                        match name {
                            Leaf::Glob => unit.globs.push(path.clone()),
                            Leaf::Named(name) => {
                                unit.bound.insert(name, (path.clone(), exported));
                            }
                        }
                        if !exported {
                            unit.uses.push(path);
                        }
                    }
                    i = end;
                    continue;
                }
                _ => {}
            }
            // A path in the code: words joined by `::`, not preceded by one.
            if let Some(first) = word(i) {
                let preceded = i > 0 && tokens[i - 1] == Token::PathSeparator;
                if !preceded && tokens.get(i + 1) == Some(&Token::PathSeparator) {
                    let mut path = vec![first.to_string()];
                    let mut j = i + 1;
                    while tokens.get(j) == Some(&Token::PathSeparator) {
                        match tokens.get(j + 1) {
                            Some(Token::Word(w)) => path.push(w.clone()),
                            _ => break,
                        }
                        j += 2;
                    }
                    unit.uses.push(path);
                    i = j;
                    continue;
                }
            }
            i += 1;
        }
        unit.tokens = tokens;
        unit
    }
}

/// A leaf of a `use` tree.
enum Leaf {
    Named(String),
    Glob,
}

/// The leaves of the `use` tree `tokens` under `prefix`: each path and the
/// name it binds.
fn use_tree(tokens: &[Token], prefix: Vec<String>, leaves: &mut Vec<(Vec<String>, Leaf)>) {
    let mut path = prefix;
    let mut i = 0;
    while i < tokens.len() {
        match &tokens[i] {
            Token::Word(w) if w == "as" => {
                if let Some(Token::Word(alias)) = tokens.get(i + 1) {
                    leaves.push((path.clone(), Leaf::Named(alias.clone())));
                }
                return;
            }
            Token::Word(w) => path.push(w.clone()),
            Token::PathSeparator => {}
            Token::Punct('*') => {
                leaves.push((path, Leaf::Glob));
                return;
            }
            Token::Punct('{') => {
                // Split the group's members at its top-level commas.
                let mut depth = 0;
                let mut start = i + 1;
                for j in i + 1..tokens.len() {
                    match tokens[j] {
                        Token::Punct('{') => depth += 1,
                        Token::Punct('}') if depth == 0 => {
                            use_tree(&tokens[start..j], path.clone(), leaves);
                            return;
                        }
                        Token::Punct('}') => depth -= 1,
                        Token::Punct(',') if depth == 0 => {
                            use_tree(&tokens[start..j], path.clone(), leaves);
                            start = j + 1;
                        }
                        _ => {}
                    }
                }
                return;
            }
            _ => {}
        }
        i += 1;
    }
    // `use a::b::{self}` binds `b`; `use a::b` binds `b`.
    if path.last().is_some_and(|l| l == "self") {
        path.pop();
    }
    if let Some(name) = path.last().cloned() {
        leaves.push((path, Leaf::Named(name)));
    }
}

/// The tokens of `code`: comments, strings, byte strings, raw strings and
/// characters left out (a lifetime stays a word after its `'`).
fn tokenize(code: &str) -> Vec<Token> {
    let chars: Vec<char> = code.chars().collect();
    let is_word = |c: char| c.is_alphanumeric() || c == '_' || c == '$';
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let next = chars.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < chars.len() && chars[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < chars.len() {
                if chars[i] == '/' && chars.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if chars[i] == '*' && chars.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if c == 'r' && (next == Some('"') || (next == Some('#') && raw_string_at(&chars, i + 1))) {
            // r"…" or r#"…"#: ends at a quote followed by as many hashes.
            let hashes = chars[i + 1..].iter().take_while(|&&c| c == '#').count();
            i += 2 + hashes;
            while i < chars.len() {
                if chars[i] == '"' && chars[i + 1..].iter().take(hashes).filter(|&&c| c == '#').count() == hashes {
                    i += 1 + hashes;
                    break;
                }
                i += 1;
            }
        } else if c == '"' {
            i += 1;
            while i < chars.len() && chars[i] != '"' {
                i += if chars[i] == '\\' { 2 } else { 1 };
            }
            i += 1;
        } else if c == '\'' {
            // A character ('a', '\n', '\u{…}') or a lifetime ('a).
            if next == Some('\\') {
                i += 2;
                while i < chars.len() && chars[i] != '\'' {
                    i += 1;
                }
                i += 1;
            } else if chars.get(i + 2) == Some(&'\'') {
                i += 3;
            } else {
                i += 1;
            }
        } else if c == ':' && next == Some(':') {
            tokens.push(Token::PathSeparator);
            i += 2;
        } else if is_word(c) {
            let start = i;
            while i < chars.len() && is_word(chars[i]) {
                i += 1;
            }
            let word: String = chars[start..i].iter().collect();
            // b"…" and br"…": the prefix is no word.
            if (word == "b" || word == "br") && chars.get(i) == Some(&'"') {
                continue;
            }
            tokens.push(Token::Word(word));
        } else {
            if !c.is_whitespace() {
                tokens.push(Token::Punct(c));
            }
            i += 1;
        }
    }
    tokens
}

/// Whether `r` followed by the hashes at `at` opens a raw string.
fn raw_string_at(chars: &[char], at: usize) -> bool {
    let hashes = chars[at..].iter().take_while(|&&c| c == '#').count();
    chars.get(at + hashes) == Some(&'"')
}

/// A cycle among `edges`, if there is one, as the nodes along it (the first
/// repeated at the end).
pub fn cycle<N: Ord + Clone>(edges: &BTreeMap<N, BTreeSet<N>>) -> Option<Vec<N>> {
    cycles(edges).into_iter().next()
}

/// One cycle through each group of nodes that reach each other (each
/// strongly connected component of more than one node), as the nodes along
/// it, the first repeated at the end.
pub fn cycles<N: Ord + Clone>(edges: &BTreeMap<N, BTreeSet<N>>) -> Vec<Vec<N>> {
    let reaches = |from: &N| -> BTreeSet<N> {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.clone()];
        while let Some(node) = stack.pop() {
            for next in edges.get(&node).into_iter().flatten() {
                if seen.insert(next.clone()) {
                    stack.push(next.clone());
                }
            }
        }
        seen
    };
    let reach: BTreeMap<N, BTreeSet<N>> = edges.keys().map(|n| (n.clone(), reaches(n))).collect();
    let mut placed = BTreeSet::new();
    let mut found = Vec::new();
    for node in edges.keys() {
        if placed.contains(node) || !reach[node].contains(node) {
            continue;
        }
        let group: BTreeSet<N> =
            reach[node].iter().filter(|m| reach.get(*m).is_some_and(|r| r.contains(node))).cloned().collect();
        placed.extend(group.iter().cloned());
        // A shortest way back to `node` inside the group, breadth first.
        let mut before: BTreeMap<N, N> = BTreeMap::new();
        let mut queue = std::collections::VecDeque::from([node.clone()]);
        'search: while let Some(at) = queue.pop_front() {
            for next in edges.get(&at).into_iter().flatten().filter(|n| group.contains(*n)) {
                if next == node {
                    let mut between = Vec::new();
                    let mut back = at.clone();
                    while &back != node {
                        between.push(back.clone());
                        back = before[&back].clone();
                    }
                    let mut path = vec![node.clone()];
                    path.extend(between.into_iter().rev());
                    path.push(node.clone());
                    found.push(path);
                    break 'search;
                }
                if !before.contains_key(next) {
                    before.insert(next.clone(), at.clone());
                    queue.push_back(next.clone());
                }
            }
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A crate of the files `files` (path, text) in a fresh folder.
    fn crate_of(files: &[(&str, &str)]) -> (tempfile::TempDir, Crate) {
        let dir = tempfile::tempdir().expect("a temporary folder");
        for (path, text) in files {
            let file = dir.path().join(path);
            std::fs::create_dir_all(file.parent().expect("a folder")).expect("its folder");
            std::fs::write(&file, text).expect("written");
        }
        let krate = Crate::read(&dir.path().join("lib.rs")).expect("read");
        (dir, krate)
    }

    fn names(dir: &Path, cycle: &[PathBuf]) -> Vec<String> {
        cycle.iter().map(|p| p.strip_prefix(dir).expect("inside").display().to_string()).collect()
    }

    #[test]
    fn a_cycle_through_a_grouped_use_and_a_super_path_is_seen() {
        let (dir, krate) = crate_of(&[
            ("lib.rs", "mod a; mod b; mod c;"),
            ("a.rs", "use crate::{b::Thing, other}; pub fn call() {}"),
            ("b.rs", "use crate::c::Item; pub struct Thing;"),
            ("c/mod.rs", "mod d; pub struct Item;"),
            ("c/d.rs", "fn f() { super::super::a::call() }"),
        ]);
        // No file's cycle (c's mod.rs does not use d.rs) …
        assert_eq!(cycle(&krate.file_edges()), None);
        // … but one of the modules, c and all below it one node.
        let found = cycle(&krate.sibling_edges()).expect("a → b → c → a");
        assert_eq!(found.iter().map(|m| m.join("::")).collect::<Vec<_>>(), ["a", "b", "c", "a"]);
        let _ = dir;
    }

    #[test]
    fn a_name_re_exported_at_the_root_leads_to_its_file() {
        // `frame` uses `crate::Kind`, which `message` defines and the root
        // re-exports; `message` uses `frame`: a cycle, though each names
        // only the root or the other.
        let (dir, krate) = crate_of(&[
            ("lib.rs", "mod frame; mod message; pub use message::Kind;"),
            ("frame.rs", "use crate::Kind; pub fn frame(k: Kind) {}"),
            ("message.rs", "pub enum Kind { A } fn send() { crate::frame::frame(Kind::A) }"),
        ]);
        let found = cycle(&krate.file_edges()).expect("frame → message → frame");
        assert_eq!(names(dir.path(), &found), ["frame.rs", "message.rs", "frame.rs"].map(String::from));
    }

    #[test]
    fn a_root_that_defines_what_its_modules_use_and_calls_one_of_them_is_a_cycle() {
        let (dir, krate) = crate_of(&[
            ("lib.rs", "mod cli; pub fn load() {} pub fn main() { cli::run() }"),
            ("cli.rs", "pub fn run() { crate::load() }"),
        ]);
        let found = cycle(&krate.file_edges()).expect("lib → cli → lib");
        assert_eq!(names(dir.path(), &found), ["cli.rs", "lib.rs", "cli.rs"].map(String::from));
    }

    #[test]
    fn re_exports_strings_comments_and_tests_are_no_edges() {
        let (_dir, krate) = crate_of(&[
            ("lib.rs", "mod a; mod b; pub use a::A; pub use b::B;"),
            ("a.rs", "pub struct A; // crate::b::B\nconst S: &str = \"crate::b::B\";\n#[cfg(test)]\nmod tests { use crate::b::B; }"),
            ("b.rs", "use crate::A; pub struct B(A);"),
        ]);
        assert_eq!(cycle(&krate.file_edges()), None);
        let edges = krate.file_edges();
        let from_b: Vec<_> =
            edges.iter().find(|(f, _)| f.ends_with("b.rs")).map(|(_, t)| t.iter().collect()).unwrap_or_default();
        assert_eq!(from_b.len(), 1, "b uses a's A through the root: {edges:?}");
        assert!(from_b[0].ends_with("a.rs"));
    }

    #[test]
    fn a_glob_of_the_parent_is_an_edge_to_the_parent() {
        let (_dir, krate) = crate_of(&[
            ("lib.rs", "mod a; pub struct Base; fn f() { a::g() }"),
            ("a.rs", "use super::*; pub fn g() -> Base { Base }"),
        ]);
        assert!(cycle(&krate.file_edges()).is_some());
    }

    #[test]
    fn a_path_attribute_is_counted() {
        let (_dir, krate) = crate_of(&[("lib.rs", "#[path = \"x.rs\"]\nmod a;"), ("x.rs", ""), ("a.rs", "")]);
        assert_eq!(krate.path_attributes().len(), 1);
    }
}
