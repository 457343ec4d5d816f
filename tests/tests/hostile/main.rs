//! The hostile-input table (docs/hostile-inputs.md), one test per row: what
//! octrace does with inputs built to break a parser, a camera, a tracer or a
//! command line. Every case runs through `host_sim::cli::run` as a user meets it
//! and asserts the exact outcome: a positioned error, exit code and no output
//! file; or a valid image of the right size, with its pixels where they are
//! knowable.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

mod files;
mod tracer;

/// Ambient-only grey (0.5) surface 1, used where only "it renders" matters.
const SURF: &str = "SURFACE 1 0.1 0.1 0.1 0.5 0.5 0.5 1 1 1 10 0 0\n";

/// The outcome of one host-sim run in a fresh directory.
struct Run {
    code: i32,
    stderr: String,
    out: PathBuf,
    dir: tempfile::TempDir,
}

impl Run {
    /// Every name in the run's directory, sorted.
    fn files(&self) -> Vec<String> {
        listing(self.dir.path())
    }
}

fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

/// Runs host-sim with `args` (without the program name); returns the exit
/// code and stdout + stderr.
fn host_sim(args: &[&std::ffi::OsStr]) -> (i32, String) {
    let (mut stdout, mut stderr) = (Vec::new(), Vec::new());
    let mut all = vec![OsString::from("host-sim")];
    all.extend(args.iter().map(OsString::from));
    let code = host_sim::cli::run(all, &mut stdout, &mut stderr);
    stdout.extend(stderr);
    (code, String::from_utf8_lossy(&stdout).into_owned())
}

/// Runs `host-sim scene.txt out.png EXTRA...` on `scene` (bytes) in a fresh
/// directory.
fn run_with(scene: &[u8], extra: &[&str]) -> Run {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.txt");
    std::fs::write(&path, scene).unwrap();
    let out = dir.path().join("out.png");
    let mut args: Vec<OsString> = vec!["host-sim".into(), path.into(), out.clone().into()];
    args.extend(extra.iter().map(OsString::from));
    let mut stderr = Vec::new();
    let code = host_sim::cli::run(args, &mut std::io::sink(), &mut stderr);
    Run { code, stderr: String::from_utf8_lossy(&stderr).into_owned(), out, dir }
}

fn run(scene: &[u8]) -> Run {
    run_with(scene, &[])
}

/// The scene is rejected with `message` at `at` (line:col), exit code 2, and
/// nothing is written.
fn rejected(scene: &[u8], at: &str, message: &str) -> Run {
    let r = run(scene);
    assert_rejected(&r, at, message);
    r
}

fn assert_rejected(r: &Run, at: &str, message: &str) {
    assert_eq!(r.code, 2, "exit code; stderr:\n{}", short(&r.stderr));
    let want = format!("scene.txt:{at}: {message}");
    assert!(r.stderr.contains(&want), "want {want:?} in:\n{}", short(&r.stderr));
    assert!(r.stderr.contains("nothing rendered"), "{}", short(&r.stderr));
    assert!(!r.out.exists(), "an output file was written");
    assert_eq!(r.files(), ["scene.txt"], "something besides the scene was left behind");
}

/// A token as error messages show it: its first 40 characters, then how
/// long it was.
fn shown(token: &str) -> String {
    let count = token.chars().count();
    if count <= 40 {
        token.to_owned()
    } else {
        format!("{}… ({count} characters)", token.chars().take(40).collect::<String>())
    }
}

/// Stderr can hold a whole hostile token: keep failure messages readable.
fn short(s: &str) -> String {
    if s.len() <= 2000 {
        s.to_owned()
    } else {
        let cut = (0..=2000).rev().find(|&i| s.is_char_boundary(i)).unwrap_or(0);
        format!("{}... ({} bytes in all)", &s[..cut], s.len())
    }
}

/// The run succeeded and left exactly the scene and a valid `w`×`h` image;
/// returns its pixels.
fn assert_image(r: &Run, w: u32, h: u32) -> host_sim::RgbImage {
    assert_eq!(r.code, 0, "stderr:\n{}", short(&r.stderr));
    assert_eq!(r.files(), ["out.png", "scene.txt"], "a temporary file was left behind");
    let img = octrace_images::formats::read(&std::fs::read(&r.out).unwrap()).expect("a valid PNG").to_rgb();
    assert_eq!((img.width, img.height), (w, h));
    assert_eq!(img.data.len(), 3 * w as usize * h as usize);
    img
}

/// Renders `scene` and returns its `w`×`h` image.
fn rendered(scene: &[u8], extra: &[&str], w: u32, h: u32) -> host_sim::RgbImage {
    assert_image(&run_with(scene, extra), w, h)
}

/// Every pixel of `img` is `rgb`.
fn assert_flat(img: &host_sim::RgbImage, rgb: [u8; 3]) {
    for y in 0..img.height {
        for x in 0..img.width {
            assert_eq!(img.pixel(x, y), rgb, "pixel ({x}, {y})");
        }
    }
}

/// Loads `text` with the library (must be valid) and renders it in `accel`
/// mode: the image and the object seen through each pixel.
fn render_lib(text: &str, accel: host_sim::AccelMode) -> host_sim::Rendered {
    let mut scene = host_sim::new_scene();
    host_sim::load_bytes("scene.txt", text.as_bytes(), &mut scene).unwrap_or_else(|e| panic!("{e}"));
    host_sim::render(&mut scene, &host_sim::RenderOptions { accel, ..Default::default() }).expect("renders")
}

const MODES: [host_sim::AccelMode; 3] =
    [host_sim::AccelMode::Naive, host_sim::AccelMode::Octree, host_sim::AccelMode::Dda];

// ---------------------------------------------------------------------------
// 1-3: empty files, comments

/// Row 1: an empty file is a valid scene: the default 320×240 raster, all
/// background (default black).
#[test]
fn row01_empty_file_renders_the_background() {
    let img = rendered(b"", &[], 320, 240);
    assert_flat(&img, [0, 0, 0]);
    // Whitespace only, of every kind, is the same.
    let img = rendered(b" \t\r\n\x0b\x0c\n  \r\n", &[], 320, 240);
    assert_flat(&img, [0, 0, 0]);
}

/// Row 2: a file of nothing but comments (both kinds, one ending the file
/// without a newline, comment markers inside comments) is the empty scene.
#[test]
fn row02_only_comments_render_the_background() {
    let text = "/* a block\n   comment /* that looks nested\n // with a line comment inside */\n\
                // a line comment /* that opens a block\n\
                /**/ /***/ /* ** / * */ // é ünïcödé ✓\n\
                // the last line has no newline";
    let img = rendered(text.as_bytes(), &[], 320, 240);
    assert_flat(&img, [0, 0, 0]);
}

/// Row 3: an unterminated `/*` is an error at the line and column where it
/// opened, wherever it is (alone, mid-statement, after a closed one).
#[test]
fn row03_unterminated_comment_names_where_it_opened() {
    let msg = "unterminated comment: this `/*` is never closed";
    rejected(b"/*", "1:1", msg);
    rejected(b"RDEPTH 1\n  /* a comment\n that never ends", "2:3", msg);
    // Inside a statement: the statement is not half-read.
    let r = rejected(format!("{SURF}SPHERE 1 1 0 /* 0 0\nLIGHT 1 0 0 0").as_bytes(), "2:14", msg);
    assert!(r.stderr.contains("1 error(s)"), "{}", r.stderr);
    // Comments do not nest: the first `*/` closes, the second opens nothing
    // and the words between are read as statements.
    rejected(b"/* a /* b */ c */", "1:14", "unknown keyword `c`");
    // A closed comment, then one left open on a later line.
    rejected(b"/* ok */\n\n\t/* /* */ /*", "3:11", msg);
}

// ---------------------------------------------------------------------------
// 4-5: numbers

/// Row 4: hostile numbers where a real number goes (a SPHERE radius) and
/// where an integer goes (RASTER and RDEPTH).
#[test]
fn row04_hostile_numbers() {
    let digits200 = format!("1{}", "0".repeat(199));
    let nines200 = "9".repeat(200);
    // A real: `SPHERE 1 <n> 0 0 0`, the radius at 1:10.
    let radius = |n: &str| format!("SPHERE 1 {n} 0 0 0\n{SURF}").into_bytes();
    let magnitude = |n: &str| format!("SPHERE radius must be at most 1e6 in magnitude, found {}", shown(n));
    rejected(&radius("1e400"), "1:10", &magnitude("1e400"));
    rejected(&radius("-1e400"), "1:10", &magnitude("-1e400"));
    rejected(&radius(&digits200), "1:10", &magnitude(&digits200));
    rejected(&radius(&nines200), "1:10", &magnitude(&nines200));
    rejected(&radius(&format!("1e{nines200}")), "1:10", &magnitude(&format!("1e{nines200}")));
    for n in ["nan", "NaN", "-nan", "inf", "-inf", "+Infinity", "0x10", "0X1p3", "1e", "1.2.3", "--1", "1_000"] {
        rejected(&radius(n), "1:10", &format!("expected a number for SPHERE radius, found `{n}`"));
    }
    rejected(&radius("-0"), "1:10", "SPHERE radius must be > 0, found -0");
    // -0, a 200-digit zero-padded 1 and a long fraction are valid numbers.
    let padded = format!("{}1", "0".repeat(199));
    let scene = |x: &str, r: &str| format!("RASTER 9 9 GAMMA 1 SPHERE 1 {r} {x} 0 0\n{SURF}");
    let reference = rendered(scene("0", "1").as_bytes(), &[], 9, 9);
    assert_eq!(reference.pixel(4, 4), [26, 26, 26], "ambient 0.1 in the middle");
    assert_eq!(reference.pixel(0, 0), [0, 0, 0], "background in the corner");
    assert_eq!(rendered(scene("-0", &padded).as_bytes(), &[], 9, 9), reference);
    let fraction = format!("1.{}", "0".repeat(198));
    assert_eq!(rendered(scene("-0.0e-999999", &fraction).as_bytes(), &[], 9, 9), reference);

    // Integers: RASTER width at 1:8, RDEPTH depth at 1:8.
    for n in ["1e400", "nan", "inf", "0x10", "16.0", "1e1"] {
        rejected(
            format!("RASTER {n} 8").as_bytes(),
            "1:8",
            &format!("expected an integer for RASTER width, found `{n}`"),
        );
        rejected(
            format!("RDEPTH {n}").as_bytes(),
            "1:8",
            &format!("expected an integer for RDEPTH depth, found `{n}`"),
        );
    }
    for n in ["-0", "0", &digits200, &nines200, &format!("-{nines200}")] {
        rejected(
            format!("RASTER {n} 8").as_bytes(),
            "1:8",
            &format!("RASTER width must be an integer from 1 to 16384, found {}", shown(n)),
        );
    }
    rejected(
        format!("RASTER 8 {digits200}").as_bytes(),
        "1:10",
        &format!("RASTER height must be an integer from 1 to 16384, found {}", shown(&digits200)),
    );
    for n in [&digits200, &nines200, "-1", "1000001"] {
        rejected(
            format!("RDEPTH {n}").as_bytes(),
            "1:8",
            &format!("RDEPTH depth must be an integer from 0 to 1000000, found {}", shown(n)),
        );
    }
    // `-0` and a zero-padded 200-digit integer are valid integers.
    rendered(format!("RDEPTH -0 RASTER {padded}6 +0007").as_bytes(), &[], 16, 7);
}

/// Row 5: RASTER is limited to 1 to 16384 on each side, and so is --size.
#[test]
fn row05_raster_out_of_range() {
    rejected(b"RASTER 0 0", "1:8", "RASTER width must be an integer from 1 to 16384, found 0");
    rejected(b"RASTER 100000 100000", "1:8", "RASTER width must be an integer from 1 to 16384, found 100000");
    rejected(b"RASTER 64 16385", "1:11", "RASTER height must be an integer from 1 to 16384, found 16385");
    for (size, why) in [
        ("100000x100000", "100000 is outside 1 to 16384"),
        ("0x0", "0 is outside 1 to 16384"),
        ("16x16385", "16385 is outside 1 to 16384"),
        ("4294967296x1", "4294967296 is outside 1 to 16384"),
        ("=-1x5", "`-1` is not a whole number"),
        ("16", "expected WxH (for example 160x128), found `16`"),
    ] {
        // `--size=V` so that clap takes a leading `-` as part of the value.
        let arg = format!("--size={}", size.trim_start_matches('='));
        let r = run_with(SURF.as_bytes(), &[&arg]);
        assert_eq!(r.code, 2, "--size {size}: {}", r.stderr);
        assert!(r.stderr.contains("--size <WxH>") && r.stderr.contains(why), "--size {size}: {}", r.stderr);
        assert_eq!(r.files(), ["scene.txt"], "--size {size}");
    }
    // The limits themselves are accepted (a 16384×1 strip of background).
    rendered(b"RASTER 16384 1", &[], 16384, 1);
    rendered(b"", &["--size", "1x16384"], 1, 16384);
}

// ---------------------------------------------------------------------------
// 6-7: cameras

/// Row 6: VIEWPOINT equal to ORIGIN (given, by default, or after rounding
/// to the format's precision) is an error at the later of the two.
#[test]
fn row06_viewpoint_equals_origin() {
    let msg = "VIEWPOINT equals ORIGIN: there is no view direction";
    rejected(b"VIEWPOINT 1 2 3\nORIGIN 1 2 3", "2:1", msg);
    rejected(b"ORIGIN 1 2 3\n\n  VIEWPOINT 1 2 3", "3:3", msg);
    // ORIGIN equal to the default VIEWPOINT (0 0 10).
    rejected(b"RDEPTH 1\nORIGIN 0 0 10", "2:1", msg);
    // 1e-10 rounds to 0 in the format's Q32.32 precision.
    rejected(b"VIEWPOINT 0 0 1e-10", "1:1", msg);
    // The smallest distinct eye (1e-9, four units of 2^-32) is a camera.
    rendered(format!("RASTER 4 4 VIEWPOINT 0 0 1e-9 {SURF}").as_bytes(), &[], 4, 4);
}

/// Row 7: UPVECTOR zero, parallel or anti-parallel to the view direction
/// (to within 2^-20 of the sine) is an error at UPVECTOR, or at the camera
/// statement when UPVECTOR is the default.
#[test]
fn row07_upvector_parallel_to_the_view() {
    let msg = "UPVECTOR is zero or parallel to the view direction (ORIGIN − VIEWPOINT)";
    rejected(b"VIEWPOINT 0 5 0\nUPVECTOR 0 -2 0", "2:1", msg);
    rejected(b"VIEWPOINT 0 5 0\nUPVECTOR 0 2 0", "2:1", msg);
    rejected(b"UPVECTOR 0 0 0", "1:1", msg);
    rejected(b"UPVECTOR 1e-9 1e-9 -1e6", "1:1", msg);
    // Nearly parallel: a sine of 1e-7.
    rejected(b"VIEWPOINT 0 5 0\nUPVECTOR 1e-7 1 0", "2:1", msg);
    // The default UPVECTOR (0 1 0) with the eye straight above ORIGIN.
    rejected(b"RDEPTH 1\nVIEWPOINT 0 10 0", "2:1", msg);
    // A sine of 1e-5 is a camera.
    rendered(b"RASTER 4 4 VIEWPOINT 0 5 0 UPVECTOR 1e-5 1 0", &[], 4, 4);
}

// ---------------------------------------------------------------------------
// 8-10: eye and lights inside objects, coincident objects
