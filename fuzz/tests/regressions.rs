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
