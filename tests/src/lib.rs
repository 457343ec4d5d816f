//! Support code for octrace's whole-pipeline tests (the tests themselves are
//! in `tests/`).

pub mod board;
pub mod budgets;
pub mod children;
pub mod firmware;
pub mod imports;
pub mod pico;
pub mod webdriver;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

/// The longest a test waits for an event (a board's answer, a browser's
/// state, a process's word) before it takes the wait for a hang: half an
/// hour. It only guards against a hang, never times the work: a test
/// waits for the event itself, and on a machine whose cores are busy with
/// other work an emulated Pico takes a hundred times a real one's time.
pub const HANG_GUARD: Duration = Duration::from_secs(30 * 60);

/// The repository root.
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Where a board build's sources appear in its firmware: the checkout's
/// path is written as this (see [`board_cargo`]).
pub const BUILD_ROOT: &str = "/octrace";

/// `cargo` in the board project `dir` (`firmware/`, a Pico template) for
/// a build for `target`, as the budgets measure it: the variables that
/// would change the build (a caller's target directory, flags, target)
/// are cleared, and the checkout's path is written as [`BUILD_ROOT`].
///
/// A panic's location names its source file, and octrace-core (outside
/// the board project's workspace) is given to rustc by its absolute path:
/// without the remap a checkout's path would add its length to each such
/// name in flash, and move the code in the Pico's XIP cache, so that the
/// figures a clone measures in /check/work/main were not those of one in
/// /work/main. `scripts/test-all` exports the same variable for every
/// board target (so that its builds and these share their artifacts); a
/// different one there fails this build, rather than build twice.
pub fn board_cargo(dir: &Path, target: &str) -> Result<Command, String> {
    let mut cargo = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
    // The project's .cargo/config.toml (runner, linker script) is found
    // from the working directory.
    cargo.current_dir(dir);
    for var in ["CARGO_TARGET_DIR", "RUSTFLAGS", "CARGO_ENCODED_RUSTFLAGS", "CARGO_BUILD_TARGET"] {
        cargo.env_remove(var);
    }
    let root = std::fs::canonicalize(repo()).map_err(|e| format!("{}: {e}", repo().display()))?;
    // Merged by cargo after the project's own target.TARGET.rustflags;
    // whitespace separates flags, so a checkout's path must have none.
    let remap = format!("--remap-path-prefix={}={BUILD_ROOT}", root.display());
    if remap.contains(char::is_whitespace) {
        return Err(format!(
            "the checkout's path has a space, which cargo's flag variables cannot carry: {}",
            root.display()
        ));
    }
    let var = format!("CARGO_TARGET_{}_RUSTFLAGS", target.to_uppercase().replace(['-', '.'], "_"));
    match std::env::var(&var) {
        Ok(exported) if exported != remap => {
            return Err(format!(
                "{var} is {exported:?}, where the board builds take {remap:?} (scripts/test-all exports it)"
            ));
        }
        _ => {}
    }
    cargo.env(var, remap);
    Ok(cargo)
}

/// Scene `name` of `scenes/` (`scenes/NAME.txt`).
pub fn scene_path(name: &str) -> PathBuf {
    repo().join("scenes").join(format!("{name}.txt"))
}

/// Every still scene in `scenes/`, sorted by name: (name, path). The
/// animations (`anim_*.txt`, see [`animations`]) are not among them.
pub fn scenes() -> Vec<(String, PathBuf)> {
    scene_files().into_iter().filter(|(name, _)| !name.starts_with(ANIMATION_PREFIX)).collect()
}

/// Every animation in `scenes/` (a scene with FRAMES, named `anim_*.txt`),
/// sorted by name: (name, path).
pub fn animations() -> Vec<(String, PathBuf)> {
    scene_files().into_iter().filter(|(name, _)| name.starts_with(ANIMATION_PREFIX)).collect()
}

/// How the names of the animations in `scenes/` begin.
const ANIMATION_PREFIX: &str = "anim_";

fn scene_files() -> Vec<(String, PathBuf)> {
    let mut v: Vec<(String, PathBuf)> = std::fs::read_dir(repo().join("scenes"))
        .expect("scenes/ exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "txt"))
        .map(|p| (p.file_stem().unwrap_or_default().to_string_lossy().into_owned(), p))
        .collect();
    v.sort();
    v
}

/// Writes host-sim's preview of a panel, as its user asks for it:
/// `host-sim scenes/SCENE.txt OUT --size WxH --color COLOR --quiet`.
pub fn host_sim_preview(scene: &str, out: &std::path::Path, size: &str, color: &str) -> Result<(), String> {
    host_sim_preview_of(&scene_path(scene), out, size, color)
}

/// [`host_sim_preview`] of the scene file at `path`.
pub fn host_sim_preview_of(
    path: &std::path::Path,
    out: &std::path::Path,
    size: &str,
    color: &str,
) -> Result<(), String> {
    host_sim_preview_with(path, out, size, color, &[])
}

/// [`host_sim_preview`] of frame `frame` of an animation (`--frame K`), as
/// a board plays it: on a panel of few levels (`color` not `rgb…`), in
/// ordered dithering (`--dither bayer`), the one method a frame's runs keep.
pub fn host_sim_frame_preview(
    scene: &str,
    frame: u32,
    out: &std::path::Path,
    size: &str,
    color: &str,
) -> Result<(), String> {
    let path = scene_path(scene);
    let frame = frame.to_string();
    let mut flags = vec!["--frame", &frame];
    if !color.starts_with("rgb") {
        flags.extend(["--dither", "bayer"]);
    }
    host_sim_preview_with(&path, out, size, color, &flags)
}

/// host-sim's preview of `path` into `out`, with `more` flags.
fn host_sim_preview_with(
    path: &std::path::Path,
    out: &std::path::Path,
    size: &str,
    color: &str,
    more: &[&str],
) -> Result<(), String> {
    let flags = ["--size", size, "--color", color, "--quiet"].into_iter().chain(more.iter().copied());
    let args = [std::ffi::OsStr::new("host-sim"), path.as_os_str(), out.as_os_str()]
        .into_iter()
        .chain(flags.map(std::ffi::OsStr::new));
    let mut stderr = Vec::new();
    match host_sim::cli::run(args, &mut Vec::new(), &mut stderr) {
        0 => Ok(()),
        code => Err(format!("host-sim exited with {code}: {}", String::from_utf8_lossy(&stderr))),
    }
}

/// Whether the tests should rewrite their expected files (`OCTRACE_BLESS=1`).
pub fn blessing() -> bool {
    std::env::var_os("OCTRACE_BLESS").is_some_and(|v| v != "0")
}

/// A small deterministic generator (xorshift64*) for property tests. The
/// seed comes from `OCTRACE_SEED` or the clock and is printed, so a failure
/// can be replayed.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed.max(1))
    }

    /// Seeded from `OCTRACE_SEED`, else the clock; prints the seed.
    pub fn from_env(test: &str) -> Rng {
        let seed = std::env::var("OCTRACE_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or_else(|| {
            std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(1, |d| d.as_nanos() as u64)
        });
        println!("{test}: seed {seed} (replay with OCTRACE_SEED={seed})");
        eprintln!("{test}: seed {seed} (replay with OCTRACE_SEED={seed})");
        Rng::new(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// Uniform in `0..n` (n > 0).
    pub fn below(&mut self, n: u32) -> u32 {
        (((self.next_u64() >> 32) * n as u64) >> 32) as u32
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The first bash block after `<!-- recipe: NAME -->` in docs/distributed.md.
pub fn recipe(name: &str) -> String {
    let doc = std::fs::read_to_string(repo().join("docs/distributed.md")).unwrap();
    let marker = format!("<!-- recipe: {name} -->");
    let after = &doc[doc.find(&marker).unwrap_or_else(|| panic!("no {marker} in docs/distributed.md"))..];
    let start = after.find("```bash\n").expect("a bash block") + "```bash\n".len();
    let end = after[start..].find("```").expect("the block ends");
    after[start..start + end].to_owned()
}

/// Runs the recipe `script` with bash in `dir`, with `host_sim` on the PATH
/// as `host-sim` (in `dir/bin`) and a HOME of its own (GNU parallel keeps
/// its state there); panics with the script's errors if it fails.
pub fn run_recipe(script: &str, dir: &std::path::Path, host_sim: &str) {
    let home = tempfile::tempdir().unwrap();
    let bin = dir.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    std::os::unix::fs::symlink(host_sim, bin.join("host-sim")).unwrap();
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    let output = std::process::Command::new("bash")
        .args(["-euo", "pipefail", "-c", script])
        .current_dir(dir)
        .env("PATH", path)
        .env("HOME", home.path())
        .output()
        .expect("bash runs");
    assert!(output.status.success(), "the recipe failed:\n{script}\n{}", String::from_utf8_lossy(&output.stderr));
}
