//! octrace's benchmarks: prints the Markdown tables of BENCHMARKS.md.
//!
//! ```text
//! cargo run --release -p host-sim --bin octrace-bench -- [TABLE…]
//! ```
//!
//! Tables: `octrace-bench --help` lists them, with what each measures.
//! No argument: all. Times are wall-clock on one thread
//! (except in `parallel`), the best of several runs; the machine is printed
//! first so every table says where it came from.

use host_sim::{
    all_cores, build_octree, load_bytes, new_scene, render, AccelMode, HostScene, Partition, RenderOptions,
};
use measure::{best_of, load, ms, scene_files, BenchError};
use octrace_core::accel::{BuildReport, OctreeConfig};
use std::path::{Path, PathBuf};
use std::time::Duration;

mod animation;
mod animation_files;
mod measure;
mod panels;

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

/// The tables, in the order a run without arguments prints them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Table {
    Scenes,
    Table51,
    Table52,
    Criterion,
    Scaling,
    Parallel,
    Palette,
    Panels,
    Spheres600,
    Animation,
    AnimationFiles,
}

impl Table {
    const ALL: [Table; 11] = [
        Table::Scenes,
        Table::Table51,
        Table::Table52,
        Table::Criterion,
        Table::Scaling,
        Table::Parallel,
        Table::Palette,
        Table::Panels,
        Table::Spheres600,
        Table::Animation,
        Table::AnimationFiles,
    ];

    /// Its name on the command line.
    fn name(self) -> &'static str {
        match self {
            Table::Scenes => "scenes",
            Table::Table51 => "table51",
            Table::Table52 => "table52",
            Table::Criterion => "criterion",
            Table::Scaling => "scaling",
            Table::Parallel => "parallel",
            Table::Palette => "palette",
            Table::Panels => "panels",
            Table::Spheres600 => "spheres600",
            Table::Animation => "animation",
            Table::AnimationFiles => "animfiles",
        }
    }

    /// What it measures, for `--help`.
    fn what(self) -> &'static str {
        match self {
            Table::Scenes => "every scene at its RASTER size, naive mode",
            Table::Table51 => "the thesis's Table 5.1: naive against the octree",
            Table::Table52 => "Table 5.2: fig5_4 by the most objects a box holds",
            Table::Criterion => "the octree's subdivision criterion",
            Table::Scaling => "random spheres, N = 10 to 100,000",
            Table::Parallel => "threads and partitions",
            Table::Palette => "the 256-colour modes",
            Table::Panels => "every dithering on every panel of few levels",
            Table::Spheres600 => "naive against dda on 600 random spheres at 800×600",
            Table::Animation => "frame-to-frame coherence on anim_fig5_1",
            Table::AnimationFiles => "the animations' GIF and APNG against ffmpeg's GIF (needs ffmpeg)",
        }
    }

    /// The command's usage: every table with what it measures.
    fn usage() -> String {
        let tables: String = Table::ALL.iter().map(|t| format!("  {:<11} {}\n", t.name(), t.what())).collect();
        format!(
            "usage: octrace-bench [TABLE...]\n\nPrints BENCHMARKS.md's tables, measured on this machine (one \
             thread but in `parallel`, best of several runs); with no TABLE, all of them in turn.\n\nTables:\n{tables}"
        )
    }

    fn from_name(name: &str) -> Result<Table, BenchError> {
        Table::ALL.into_iter().find(|t| t.name() == name).ok_or_else(|| BenchError::UnknownTable {
            name: name.to_owned(),
            known: Table::ALL.iter().map(|t| t.name()).collect(),
        })
    }

    /// Measures and prints the table, from the scenes in `dir`.
    fn print(self, dir: &Path) -> Result<(), BenchError> {
        match self {
            Table::Scenes => scenes_table(dir),
            Table::Table51 => table51(dir),
            Table::Table52 => table52(dir),
            Table::Criterion => criterion(dir),
            Table::Scaling => {
                scaling();
                Ok(())
            }
            Table::Parallel => parallel(dir),
            Table::Palette => palette_table(dir),
            Table::Panels => panels::table(dir),
            Table::Spheres600 => spheres600(dir),
            Table::Animation => animation::table(dir),
            Table::AnimationFiles => animation_files::table(dir),
        }
    }
}

/// Render time (best of `runs`), including the octree build.
fn time(
    scene: &mut HostScene,
    accel: AccelMode,
    octree: OctreeConfig,
    size: Option<(u32, u32)>,
    runs: usize,
) -> Duration {
    let options = RenderOptions { size, accel, octree, ..Default::default() };
    best_of(runs, || render(scene, &options).map(|r| r.stats)).0
}

/// Render time alone (the octree and light buffer built beforehand),
/// best of `runs`.
fn render_time(scene: &mut HostScene, options: &RenderOptions, runs: usize) -> Duration {
    (0..runs).map(|_| render(scene, options).expect("renders").wall).min().expect("a run")
}

/// The octree `mode` walks with `config`: its report, and its build's
/// time (best of `runs`).
fn octree_build(scene: &mut HostScene, mode: AccelMode, config: &OctreeConfig, runs: usize) -> (BuildReport, Duration) {
    let builds: Vec<_> = (0..runs).map(|_| build_octree(scene, mode, config).expect("an octree")).collect();
    let fastest = builds.iter().map(|(_, d)| *d).min().expect("a build");
    (builds[0].0, fastest)
}

fn scenes_table(dir: &Path) -> Result<(), BenchError> {
    println!("### Every scene at its RASTER size, naive mode, one thread\n");
    println!("| scene | size | objects | lights | rays | shadow rays | time (best of 3) | ns / pixel |");
    println!("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |");
    for path in scene_files(dir) {
        let name = path.file_stem().unwrap_or_default().to_string_lossy().into_owned();
        let mut scene = load(&path)?;
        let view = scene.view();
        let ([w, h], objects, lights) = (view.settings.raster, view.object_count(), view.lights.len());
        let naive = RenderOptions { accel: AccelMode::Naive, ..Default::default() };
        let (time, stats) = best_of(3, || render(&mut scene, &naive).map(|r| r.stats));
        let Ok(stats) = stats else { continue };
        println!(
            "| {name} | {w}×{h} | {} | {} | {} | {} | {} | {:.0} |",
            objects,
            lights,
            stats.rays,
            stats.shadow_rays,
            ms(time),
            time.as_nanos() as f64 / (w as f64 * h as f64)
        );
    }
    println!();
    Ok(())
}

fn table51(dir: &Path) -> Result<(), BenchError> {
    println!("### Table 5.1: naive against the octree (thesis) and 3DDDA (octrace)\n");
    println!("Each scene at its RASTER size; times include building the octree (default criterion).\n");
    println!("| figure | objects | thesis naive | thesis fast | thesis ratio | naive | octree | ratio | dda | ratio |");
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    // The thesis's three scenes with its minutes; then the B-spline scenes
    // it has no timings for (the 7,938-triangle free form naive only once:
    // it takes seconds).
    let rows = [
        ("fig5_1", "05:06", "08:50", "0.58×", 5),
        ("fig5_2", "54:26", "25:40", "2.12×", 5),
        ("fig5_3", "123:20", "40:52", "3.02×", 5),
        ("fig5_6", "—", "—", "—", 3),
        ("freeform", "—", "—", "—", 1),
    ];
    for (name, tn, tf, tr, runs) in rows {
        let mut scene = load(&dir.join(format!("{name}.txt")))?;
        let c = host_sim::OCTREE;
        let naive = time(&mut scene, AccelMode::Naive, c, None, runs);
        let octree = time(&mut scene, AccelMode::Octree, c, None, 3);
        let dda = time(&mut scene, AccelMode::Dda, c, None, 3);
        let r = |t: Duration| naive.as_secs_f64() / t.as_secs_f64();
        println!(
            "| {name} | {} | {tn} | {tf} | {tr} | {} | {} | {:.2}× | {} | {:.2}× |",
            scene.view().object_count(),
            ms(naive),
            ms(octree),
            r(octree),
            ms(dda),
            r(dda)
        );
    }
    println!();
    Ok(())
}

fn table52(dir: &Path) -> Result<(), BenchError> {
    println!("### Table 5.2: fig5_4 (24 spheres) by the maximum number of objects per box\n");
    println!("| objects per box | thesis (octree) | octree | dda | boxes | leaves | references | depth |");
    println!("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    let mut scene = load(&dir.join("fig5_4.txt"))?;
    let default = host_sim::OCTREE;
    for (max, thesis) in [(2usize, "22:21"), (6, "17:52"), (8, "28:36"), (default.max_objects, "(default)")] {
        let c = OctreeConfig { max_objects: max, ..default };
        let octree = time(&mut scene, AccelMode::Octree, c, None, 5);
        let dda = time(&mut scene, AccelMode::Dda, c, None, 5);
        let (report, _) = octree_build(&mut scene, AccelMode::Dda, &c, 1);
        println!(
            "| {max} | {thesis} | {} | {} | {} | {} | {} | {} |",
            ms(octree),
            ms(dda),
            report.nodes,
            report.leaves,
            report.references,
            report.depth
        );
    }
    let naive = time(&mut scene, AccelMode::Naive, default, None, 5);
    println!("\nnaive on the same scene: {}\n", ms(naive));
    Ok(())
}

/// `n` non-overlapping spheres of equal radius dropped at random (random
/// sequential adsorption) on the 16 × 12 rectangle the camera sees face on,
/// the radius chosen so that they cover 40 % of it for every `n`: every
/// image has the same share of pixels on spheres and of rays that pass
/// between them.
fn carpet(n: usize, seed: u64) -> String {
    let (w, h) = (16.0f64, 12.0f64);
    let r = (0.4 * w * h / (n as f64 * std::f64::consts::PI)).sqrt();
    let mut state = seed | 1;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    // A grid of cells of side 2r: a new sphere only needs its 3×3 cells.
    let (cols, rows) = ((w / (2.0 * r)).ceil() as usize + 1, (h / (2.0 * r)).ceil() as usize + 1);
    let mut grid: Vec<Vec<(f64, f64)>> = vec![Vec::new(); cols * rows];
    let mut placed = Vec::with_capacity(n);
    while placed.len() < n {
        let (x, z) = (r + next() * (w - 2.0 * r), r + next() * (h - 2.0 * r));
        let (cx, cz) = ((x / (2.0 * r)) as usize, (z / (2.0 * r)) as usize);
        let clear = (cx.saturating_sub(1)..=(cx + 1).min(cols - 1)).all(|i| {
            (cz.saturating_sub(1)..=(cz + 1).min(rows - 1))
                .all(|j| grid[j * cols + i].iter().all(|&(px, pz)| (px - x).powi(2) + (pz - z).powi(2) >= 4.0 * r * r))
        });
        if clear {
            grid[cz * cols + cx].push((x, z));
            placed.push((x - w / 2.0, z - h / 2.0));
        }
    }
    let mut s = format!(
        "RASTER 160 120 RDEPTH 1 VIEWPORT {w} {h}\nVIEWPOINT 0 20 0 ORIGIN 0 0 0 UPVECTOR 0 0 -1\nLIGHT 22 4 20 6\n\
         SURFACE 1 0.1 0.05 0.05 0.8 0.3 0.2 0.6 0.6 0.6 30 0.2 0\n\
         SURFACE 2 0.05 0.05 0.1 0.2 0.4 0.8 0.6 0.6 0.6 30 0.2 0\n"
    );
    for (i, (x, z)) in placed.into_iter().enumerate() {
        s += &format!("SPHERE {} {r:.6} {x:.6} {r:.6} {z:.6}\n", 1 + i % 2);
    }
    s
}

fn scaling() {
    println!("### Scaling: N random spheres covering 40 % of the same screen area, 160×120\n");
    println!("Times per pixel are rendering only; building the structure is its own column.");
    println!("Naive is not run beyond 10,000 spheres (it would take hours); memory is the");
    println!("octree's arenas.\n");
    println!("| N | naive ns/pixel | octree ns/pixel | dda ns/pixel | build | octree memory | leaves | depth |");
    println!("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    let pixels = 160.0 * 120.0;
    let mut dda_times = Vec::new();
    for n in [10usize, 100, 1_000, 10_000, 100_000] {
        let text = carpet(n, 0x9e37_79b9_7f4a_7c15 ^ n as u64);
        let mut scene = new_scene();
        load_bytes("carpet", text.as_bytes(), &mut scene).expect("the carpet parses");
        let c = host_sim::OCTREE;
        let per_px = |d: Duration| format!("{:.0}", d.as_nanos() as f64 / pixels);
        let naive = if n <= 10_000 { per_px(time(&mut scene, AccelMode::Naive, c, None, 1)) } else { "—".into() };
        let mut walk =
            |mode| render_time(&mut scene, &RenderOptions { accel: mode, octree: c, ..Default::default() }, 3);
        let octree = walk(AccelMode::Octree);
        let dda = walk(AccelMode::Dda);
        dda_times.push((n, dda));
        let (report, build) = octree_build(&mut scene, AccelMode::Dda, &c, 3);
        println!(
            "| {n} | {naive} | {} | {} | {} | {:.1} MB | {} | {} |",
            per_px(octree),
            per_px(dda),
            ms(build),
            report.bytes as f64 / 1e6,
            report.leaves,
            report.depth
        );
    }
    let t = |n| dda_times.iter().find(|(m, _)| *m == n).map(|(_, d)| d.as_secs_f64()).unwrap_or(f64::NAN);
    println!("\ndda: time(N = 10,000) / time(N = 10) = {:.2}\n", t(10_000) / t(10));
}

fn criterion(dir: &Path) -> Result<(), BenchError> {
    println!("### Choosing the default criterion (dda, ms, best of 3)\n");
    let combos = [(1usize, 12u32), (2, 12), (3, 12), (4, 12), (6, 12), (8, 12), (4, 8), (4, 16)];
    print!("| scene |");
    for (m, d) in combos {
        print!(" ≤ {m}, depth {d} |");
    }
    println!();
    println!("| --- |{}", " ---: |".repeat(combos.len()));
    for path in scene_files(dir) {
        let name = path.file_stem().unwrap_or_default().to_string_lossy().into_owned();
        let mut scene = load(&path)?;
        if scene.view().object_count() <= AccelMode::AUTO_NAIVE_UP_TO {
            continue;
        }
        print!("| {name} |");
        for (m, d) in combos {
            let c = OctreeConfig { max_objects: m, max_depth: d, ..host_sim::OCTREE };
            print!(" {:.1} |", time(&mut scene, AccelMode::Dda, c, None, 3).as_secs_f64() * 1e3);
        }
        println!();
    }
    println!();
    Ok(())
}

/// A scene whose work is all in one corner of the image: 60 reflective
/// spheres in the top-left quarter, the rest background.
fn corner() -> String {
    let mut s = String::from(
        "RASTER 800 600 RDEPTH 3\nVIEWPOINT 0 0 20 ORIGIN 0 0 0\nLIGHT 30 -10 10 20\n\
         SURFACE 1 0.1 0.1 0.1 0.6 0.5 0.4 0.8 0.8 0.8 40 0.5 0\n",
    );
    for i in 0..60 {
        let (x, y) = (-9.5 + (i % 10) as f64 * 0.8, 1.2 + (i / 10) as f64 * 0.8);
        s += &format!("SPHERE 1 0.38 {x:.2} {y:.2} {:.2}\n", (i % 3) as f64 * 0.3);
    }
    s
}

fn parallel(dir: &Path) -> Result<(), BenchError> {
    let cores = all_cores();
    println!("### Parallel rendering: speed-up and idle time\n");
    println!("dda mode, octree built once beforehand; wall-clock time of the render, best of 3. Idle is the");
    println!("share of thread-time spent waiting for the last thread: Σ(wall − busy) / (threads × wall).\n");
    println!("| scene | size | partition | threads | time | speed-up | idle |");
    println!("| --- | --- | --- | ---: | ---: | ---: | ---: |");
    let mut corner_scene = new_scene();
    load_bytes("corner", corner().as_bytes(), &mut corner_scene).expect("the corner scene parses");
    let cases: [(&str, Box<HostScene>, (u32, u32)); 3] = [
        ("fig5_3", load(&dir.join("fig5_3.txt"))?, (800, 600)),
        ("fig5_8", load(&dir.join("fig5_8.txt"))?, (800, 600)),
        ("corner", corner_scene, (800, 600)),
    ];
    for (name, mut scene, size) in cases {
        let (scene, size) = (&mut *scene, &size);
        let mut one = None;
        let mut runs = vec![(Partition::Tiles, 1)];
        for threads in [2, 4].into_iter().chain((cores > 4).then_some(cores)) {
            runs.push((Partition::Tiles, threads));
            runs.push((Partition::Equal4, threads));
        }
        for (partition, threads) in runs {
            let options =
                RenderOptions { size: Some(*size), accel: AccelMode::Dda, threads, partition, ..Default::default() };
            let rendered =
                (0..3).map(|_| render(scene, &options).expect("renders")).min_by_key(|r| r.wall).expect("three runs");
            let wall = rendered.wall.as_secs_f64();
            let one_thread = *one.get_or_insert(wall);
            let idle: f64 = rendered.busy.iter().map(|b| wall - b.as_secs_f64()).sum::<f64>() / (threads as f64 * wall);
            let partition = match partition {
                Partition::Tiles => "tiles 32×32",
                Partition::Equal4 => "equal 4 (thesis)",
            };
            println!(
                "| {name} | {}×{} | {partition} | {threads} | {} | {:.2}× | {:.0} % |",
                size.0,
                size.1,
                ms(rendered.wall),
                one_thread / wall,
                100.0 * idle.max(0.0)
            );
        }
    }
    println!();
    Ok(())
}

/// Every scene in every palette mode: entries used, PSNR against the
/// truecolour render and the cost of the mapping per pixel.
fn palette_table(dir: &Path) -> Result<(), BenchError> {
    use octrace_images::formats::Image;
    use octrace_images::palette::{self, PaletteMode};
    println!("### 256-colour modes: every scene at its RASTER size\n");
    println!("Colours: distinct colours in the image (entries of the 256-colour table in use). PSNR against the");
    println!("truecolour render. Cost: the mapping alone per pixel, best of 5 (the render is the same for all).\n");
    println!("| scene | truecolour colours | scan | dither | coarse | gray |");
    println!("| --- | ---: | --- | --- | --- | --- |");
    let mut cost = [Duration::ZERO; 5];
    let mut pixels = 0.0;
    for path in scene_files(dir) {
        let name = path.file_stem().unwrap_or_default().to_string_lossy().into_owned();
        let mut scene = load(&path)?;
        let Ok(rendered) = render(&mut scene, &RenderOptions { threads: all_cores(), ..Default::default() }) else {
            continue;
        };
        pixels += (rendered.image.width * rendered.image.height) as f64;
        print!("| {name} | {} |", palette::colors_used(&Image::Rgb(rendered.image.clone())));
        for (i, mode) in PaletteMode::ALL.into_iter().enumerate().skip(1) {
            let (time, image) = best_of(5, || palette::apply(&rendered.image, &rendered.objects, mode));
            cost[i] += time;
            let psnr = palette::psnr(&rendered.image, &image.to_rgb());
            print!(" {} colours, {psnr:.1} dB |", palette::colors_used(&image));
        }
        println!();
    }
    print!("| cost per pixel | |");
    for c in &cost[1..] {
        print!(" {:.1} ns |", c.as_nanos() as f64 / pixels);
    }
    println!("\n");
    Ok(())
}

/// Issue 14's target 2: the 600 random spheres of `scenes/spheres600.txt`
/// at 800×600, naive against dda, the render alone (octree built
/// beforehand) and with the build. The two modes' runs alternate, so that
/// a busy spell of a shared machine weighs on both.
fn spheres600(dir: &Path) -> Result<(), BenchError> {
    println!("### 600 random spheres at 800×600: naive against dda (one thread, best of 3, alternating)\n");
    println!("| scene | naive | dda render | dda build | render ratio | ratio with build |");
    println!("| --- | ---: | ---: | ---: | ---: | ---: |");
    let mut scene = load(&dir.join("spheres600.txt"))?;
    let c = host_sim::OCTREE;
    let size = Some((800, 600));
    let (_, build) = octree_build(&mut scene, AccelMode::Dda, &c, 3);
    let options = RenderOptions { size, accel: AccelMode::Dda, octree: c, ..Default::default() };
    let (mut naive, mut render) = (Duration::MAX, Duration::MAX);
    for _ in 0..3 {
        naive = naive.min(time(&mut scene, AccelMode::Naive, c, size, 1));
        render = render.min(render_time(&mut scene, &options, 1));
    }
    let r = |t: Duration| naive.as_secs_f64() / t.as_secs_f64();
    println!(
        "| spheres600 | {} | {} | {} | {:.1}× | {:.1}× |\n",
        ms(naive),
        ms(render),
        ms(build),
        r(render),
        r(render + build)
    );
    Ok(())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "--help" || a == "-h") {
        print!("{}", Table::usage());
        return;
    }
    let scenes = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let tables = if args.is_empty() {
        Ok(Table::ALL.to_vec())
    } else {
        args.iter().map(|name| Table::from_name(name)).collect()
    };
    let run = tables.and_then(|tables| {
        println!("Machine: {}\n", machine());
        tables.into_iter().try_for_each(|table| table.print(&scenes))
    });
    if let Err(e) = run {
        eprintln!("{e}");
        std::process::exit(e.exit_code());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_table_is_found_by_its_name_and_an_unknown_one_is_an_error() {
        for table in Table::ALL {
            assert_eq!(Table::from_name(table.name()).ok(), Some(table));
        }
        let usage = Table::usage();
        assert!(Table::ALL.iter().all(|t| usage.contains(&format!("  {:<11} {}\n", t.name(), t.what()))), "{usage}");
        let e = Table::from_name("table53").unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert!(e.to_string().contains("unknown table `table53` (known: scenes, table51"), "{e}");
    }

    #[test]
    fn a_scene_that_cannot_be_read_says_which_and_exits_1() {
        let e = load(Path::new("/nonexistent/scene.txt")).unwrap_err();
        assert_eq!(e.exit_code(), 1);
        assert!(e.to_string().starts_with("octrace-bench: cannot read /nonexistent/scene.txt: "), "{e}");
    }
}
