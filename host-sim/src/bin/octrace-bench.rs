//! octrace's benchmarks: prints Markdown tables for BENCHMARKS.md.
//!
//!     cargo run --release -p host-sim --bin octrace-bench -- [scenes]
//!
//! Times are the best of several runs on one thread; the machine is printed
//! first so every table says where it came from.

use host_sim::{load_file, new_scene, render, AccelMode, RenderOptions};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_owned())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    format!("{cpu}, {cores} cores, {} {}", std::env::consts::OS, std::env::consts::ARCH)
}

/// The best of `runs` timings of `f`.
fn best_of<T>(runs: usize, mut f: impl FnMut() -> T) -> (Duration, T) {
    let mut best = Duration::MAX;
    let mut last = None;
    for _ in 0..runs {
        let t = Instant::now();
        let r = f();
        best = best.min(t.elapsed());
        last = Some(r);
    }
    (best, last.expect("at least one run"))
}

fn scene_files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> =
        std::fs::read_dir(dir).map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect()).unwrap_or_default();
    v.retain(|p| p.extension().is_some_and(|x| x == "txt"));
    v.sort();
    v
}

fn scenes_table(dir: &Path) {
    println!("### Every scene at its RASTER size, naive mode, one thread\n");
    println!("| scene | size | objects | lights | rays | shadow rays | time (best of 3) | ns / pixel |");
    println!("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |");
    for path in scene_files(dir) {
        let name = path.file_stem().unwrap_or_default().to_string_lossy().into_owned();
        let mut scene = new_scene();
        if let Err(e) = load_file(&path, &mut scene) {
            println!("| {name} | error: {e} |");
            continue;
        }
        let view = scene.view();
        let [w, h] = view.settings.raster;
        let naive = RenderOptions { accel: AccelMode::Naive, ..Default::default() };
        let (time, stats) = best_of(3, || render(&scene, &naive).map(|r| r.stats));
        let Ok(stats) = stats else { continue };
        println!(
            "| {name} | {w}×{h} | {} | {} | {} | {} | {:.1} ms | {:.0} |",
            view.object_count(),
            view.lights.len(),
            stats.rays,
            stats.shadow_rays,
            time.as_secs_f64() * 1e3,
            time.as_nanos() as f64 / (w as f64 * h as f64)
        );
    }
    println!();
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let which: Vec<&str> = if args.is_empty() { vec!["scenes"] } else { args.iter().map(String::as_str).collect() };
    println!("Machine: {}\n", machine());
    for w in which {
        match w {
            "scenes" => scenes_table(&root.join("scenes")),
            other => {
                eprintln!("octrace-bench: unknown table `{other}` (known: scenes)");
                std::process::exit(2);
            }
        }
    }
}
