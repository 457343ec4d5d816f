//! Every kept reproducer (`regressions/`) and every seed (`seeds/` and the
//! project's own `../scenes/`) through the fuzz targets' checks, on stable
//! Rust: a fixed finding stays fixed. `regressions/parse/` inputs get the
//! parse check, `regressions/render/` and the seeds both checks.

use std::fs;
use std::path::{Path, PathBuf};

fn files(dir: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut files: Vec<PathBuf> = match fs::read_dir(&dir) {
        Ok(entries) => entries
            .map(|e| e.expect("readable directory").path())
            .filter(|p| p.extension().is_some_and(|x| x == "txt"))
            .collect(),
        Err(_) => Vec::new(),
    };
    files.sort();
    files
}

fn run(dir: &str, render: bool) -> usize {
    let files = files(dir);
    for path in &files {
        let data = fs::read(path).expect("readable input");
        println!("{}", path.display());
        octrace_fuzz::check_parse(&data);
        if render {
            octrace_fuzz::check_render(&data);
        }
    }
    files.len()
}

#[test]
fn parse_regressions() {
    run("regressions/parse", false);
}

#[test]
fn render_regressions() {
    assert!(run("regressions/render", true) > 0, "the render reproducers are missing");
}

#[test]
fn seeds() {
    assert!(run("seeds", true) > 10, "the seed corpus is missing");
    assert!(run("../scenes", true) > 5, "the scenes are missing");
}

/// Every file of `dir` (any name).
fn all_files(dir: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut files: Vec<PathBuf> = match fs::read_dir(&dir) {
        Ok(entries) => entries.map(|e| e.expect("readable directory").path()).collect(),
        Err(_) => Vec::new(),
    };
    files.sort();
    files
}

#[test]
fn link_regressions_and_seeds() {
    let seeds = all_files("link-seeds");
    assert!(seeds.len() >= 8, "the link's seed corpus is missing");
    for path in all_files("regressions/link").iter().chain(&seeds) {
        println!("{}", path.display());
        octrace_fuzz::check_link(&fs::read(path).expect("readable input"));
    }
}

/// The files of `dir` are `seeds` (a change of the protocol changes them:
/// re-bless with OCTRACE_BLESS=1).
fn seeds_are_current(dir: &str, seeds: Vec<(&str, Vec<u8>)>) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let bless = std::env::var_os("OCTRACE_BLESS").is_some_and(|v| v != "0");
    for (name, bytes) in seeds {
        let path = dir.join(name);
        if bless {
            fs::create_dir_all(&dir).unwrap();
            fs::write(&path, &bytes).unwrap();
        }
        assert!(
            fs::read(&path).is_ok_and(|kept| kept == bytes),
            "{} is not current: OCTRACE_BLESS=1 rewrites it",
            path.display()
        );
    }
}

/// The link's seeds are what today's encoder writes.
#[test]
fn link_seeds_are_current() {
    seeds_are_current("link-seeds", octrace_fuzz::link_seeds());
}

#[test]
fn board_loop_regressions_and_seeds() {
    let seeds = all_files("board-loop-seeds");
    assert!(seeds.len() >= 4, "the board loop's seed corpus is missing");
    // The link's seeds too, as more inputs (read as pieces, they are
    // other streams).
    for path in all_files("regressions/board_loop").iter().chain(&seeds).chain(&all_files("link-seeds")) {
        println!("{}", path.display());
        octrace_fuzz::check_board_loop(&fs::read(path).expect("readable input"));
    }
}

/// The board loop's seeds are what today's encoder writes.
#[test]
fn board_loop_seeds_are_current() {
    seeds_are_current("board-loop-seeds", octrace_fuzz::board_loop_seeds());
}
