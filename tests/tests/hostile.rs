//! The hostile-input table (docs/hostile-inputs.md), one test per row: what
//! octrace does with inputs built to break a parser, a camera, a tracer or a
//! command line. Every case runs through `host_sim::cli::run` as a user meets it
//! and asserts the exact outcome: a positioned error, exit code and no output
//! file; or a valid image of the right size, with its pixels where they are
//! knowable.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

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

/// Surfaces with only an ambient colour (GAMMA 1: pixel = 255 × ambient).
const RED: &str = "SURFACE 1 0.6 0 0  0 0 0  0 0 0  0 0 0\n";
const GREEN: &str = "SURFACE 2 0 0.6 0  0 0 0  0 0 0  0 0 0\n";
const RED_PX: [u8; 3] = [153, 0, 0];
const GREEN_PX: [u8; 3] = [0, 153, 0];

/// Row 8: with the eye inside a sphere every pixel shows the sphere's
/// inside; lit from inside, its inner face is shaded with the normal facing
/// the eye.
#[test]
fn row08_eye_inside_a_sphere() {
    let scene = format!("RASTER 15 15 GAMMA 1 BACKGROUND 0 0 1 VIEWPOINT 0 0 0 ORIGIN 0 0 -1 SPHERE 1 5 0 0 0 {RED}");
    assert_flat(&rendered(scene.as_bytes(), &[], 15, 15), RED_PX);
    for mode in MODES {
        let r = render_lib(&scene, mode);
        assert!(r.objects.iter().all(|&o| o == 0), "{mode:?}: every pixel sees sphere 0");
        assert!(r.image.data.chunks(3).all(|p| p == RED_PX), "{mode:?}");
    }
    // A light at the eye, the sphere's centre: N·L = 1 and d = 5 at every
    // point of the inner face: ambient 0.1 + 6/(5 + 1) · 0.5 = 0.6.
    let lit = "RASTER 15 15 GAMMA 1 BACKGROUND 0 0 1 VIEWPOINT 0 0 0 ORIGIN 0 0 -1 SPHERE 1 5 0 0 0 \
               LIGHT 6 0 0 0 SURFACE 1 0.1 0.1 0.1 0.5 0.5 0.5 0 0 0 1 0 0";
    // With the light at the centre the normal points at it everywhere, so
    // every pixel is that colour.
    let img = rendered(lit.as_bytes(), &[], 15, 15);
    for y in 0..15 {
        for x in 0..15 {
            let p = img.pixel(x, y);
            assert!(p.iter().all(|&c| c.abs_diff(153) <= 1), "({x}, {y}): {p:?}, want 153 (0.6)");
        }
    }
    // The eye exactly on the sphere's surface, looking in and looking out:
    // renders (the image there is a matter of rounding, not checked).
    for look in ["0 0 -1", "0 0 10"] {
        let on = format!("RASTER 8 8 VIEWPOINT 0 0 5 ORIGIN {look} SPHERE 1 5 0 0 0 LIGHT 1 0 0 0 {SURF}");
        rendered(on.as_bytes(), &[], 8, 8);
    }
}

/// Row 9: a light inside a closed object (sphere, box) lights nothing
/// outside it: another object beside it shows its ambient colour only.
#[test]
fn row09_light_inside_an_object_is_blocked() {
    // Surface 2: ambient 0.2, diffuse 1, no specular.
    let grey = "SURFACE 2 0.2 0.2 0.2 1 1 1 0 0 0 1 0 0\n";
    let beside = format!("RASTER 32 16 GAMMA 1 SPHERE 2 1 2 0 0 LIGHT 10 -2 0 0 {RED}{grey}");
    // Without a container the light reaches the sphere beside it.
    let open = render_lib(&beside, host_sim::AccelMode::Naive);
    assert!(
        open.objects.iter().zip(open.image.data.chunks(3)).any(|(&o, p)| o == 0 && p[0] > 60),
        "the control scene lights the sphere"
    );
    for container in ["SPHERE 1 1 -2 0 0", "BOX 1 -2 0 0 1 1 1", "SUPERQUADRIC 1 4 -2 0 0 1 1 1"] {
        let scene = format!("{beside}{container}\n");
        let img = rendered(scene.as_bytes(), &[], 32, 16);
        for mode in MODES {
            let r = render_lib(&scene, mode);
            assert_eq!(r.image, img, "{container}: {mode:?} differs from host-sim");
            let mut seen = [0; 2];
            for (&o, p) in r.objects.iter().zip(r.image.data.chunks(3)) {
                match o {
                    0 => assert_eq!(p, [51, 51, 51], "{container}: the sphere beside it is lit"),
                    1 => assert_eq!(p, RED_PX, "{container}: the container's outside is lit"),
                    _ => continue,
                }
                seen[o as usize] += 1;
            }
            assert!(seen[0] > 10 && seen[1] > 10, "{container}: both objects in view: {seen:?}");
        }
    }
}

/// Row 10: coincident objects: the earlier in the file wins, in every
/// acceleration mode, whatever the surface numbers.
#[test]
fn row10_coincident_objects_the_earlier_wins() {
    let cases = [
        ("SPHERE 1 1 0 0 0  SPHERE 2 1 0 0 0", RED_PX),
        ("SPHERE 2 1 0 0 0  SPHERE 1 1 0 0 0", GREEN_PX),
        ("TRIANGLE 1 -1 -1 0 1 -1 0 0 1 0  TRIANGLE 2 -1 -1 0 1 -1 0 0 1 0", RED_PX),
        ("TRIANGLE 2 -1 -1 0 1 -1 0 0 1 0  TRIANGLE 1 -1 -1 0 1 -1 0 0 1 0", GREEN_PX),
        ("RECTANGLE 2 -1 -1 0 1 -1 0 1 1 0 -1 1 0  RECTANGLE 1 -1 -1 0 1 -1 0 1 1 0 -1 1 0", GREEN_PX),
        ("BOX 1 0 0 0 1 1 1  BOX 2 0 0 0 1 1 1", RED_PX),
    ];
    for (objects, want) in cases {
        // From the front and from behind (the back of a triangle).
        for eye in ["0 0 10", "0 0 -10"] {
            let scene = format!("RASTER 9 9 GAMMA 1 VIEWPOINT {eye} {objects} {RED}{GREEN}");
            for accel in ["naive", "octree", "dda"] {
                let img = rendered(scene.as_bytes(), &["--accel", accel], 9, 9);
                assert_eq!(img.pixel(4, 4), want, "{objects} from {eye}, {accel}");
            }
            for mode in MODES {
                let r = render_lib(&scene, mode);
                assert_eq!(r.objects[4 * 9 + 4], 0, "{objects} from {eye}, {mode:?}: object 0 wins");
                assert!(r.objects.iter().all(|&o| o != 1), "{objects} from {eye}, {mode:?}: object 1 is never seen");
            }
        }
    }
}

/// Row 10b: many coincident objects (more than the octree's 4 per box, more
/// than the 16 auto renders without an octree) still give the first in the
/// file, and in about the time of as many separate objects.
#[test]
fn row10_many_coincident_objects_render_quickly() {
    let stack = |first: &str, rest: &str, n: usize| {
        let mut text = format!("RASTER 9 9 GAMMA 1 {RED}{GREEN}{first}\n");
        for _ in 1..n {
            text.push_str(rest);
            text.push('\n');
        }
        text
    };
    for (name, text) in [
        ("100 spheres", stack("SPHERE 1 1 0 0 0", "SPHERE 2 1 0 0 0", 100)),
        ("17 triangles", stack("TRIANGLE 1 -1 -1 0 1 -1 0 0 1 0", "TRIANGLE 2 -1 -1 0 1 -1 0 0 1 0", 17)),
    ] {
        for accel in ["auto", "naive", "octree", "dda"] {
            let started = Instant::now();
            let img = rendered(text.as_bytes(), &["--accel", accel], 9, 9);
            let took = started.elapsed();
            println!("{name}, {accel}: {took:.2?}");
            assert_eq!(img.pixel(4, 4), RED_PX, "{name}, {accel}");
            assert!(took < Duration::from_secs(5), "{name}, {accel}: {took:?} for 81 pixels");
        }
    }
}

// ---------------------------------------------------------------------------
// 11-12: degenerate shapes

/// Row 11: a triangle with collinear or repeated corners is an error at its
/// keyword; one too thin to represent at the scene's scale is too.
#[test]
fn row11_degenerate_triangle() {
    let collinear = "TRIANGLE is degenerate: its corners are collinear (zero area)";
    for corners in [
        "0 0 0  1 1 1  3 3 3",      // collinear
        "1 2 3  1 2 3  0 0 0",      // two corners repeated
        "5 5 5  5 5 5  5 5 5",      // one point
        "0 0 0  1e6 0 0  -1e6 0 0", // collinear across the whole range
        "-0 0 0  0 -0 0  7 0 0",    // -0 is 0
    ] {
        rejected(format!("{SURF}  TRIANGLE 1 {corners}").as_bytes(), "2:3", collinear);
    }
    // A sliver of width 1e-9 next to a light 1e6 away: not collinear in the
    // text, but nothing after scaling the scene to the tracer's range.
    rejected(
        format!("{SURF}TRIANGLE 1 0 0 0 1 0 0 0 1e-9 0 LIGHT 1 1e6 0 0").as_bytes(),
        "2:1",
        "TRIANGLE is too small to represent next to the rest of the scene \
         (sizes below about 2^-29 of the scene's extent round to 0 in fixed point)",
    );
    // A representable sliver renders.
    let sliver = format!("RASTER 16 16 {SURF}TRIANGLE 1 -3 0 0 3 1e-3 0 3 0 0 LIGHT 1 0 0 10");
    rendered(sliver.as_bytes(), &[], 16, 16);
}

/// Row 12: a rectangle whose fourth corner is off the plane of the other
/// three by more than 2^-10 of its longest edge is an error at its keyword.
#[test]
fn row12_non_planar_rectangle() {
    let msg = "RECTANGLE is not planar: its fourth corner is off the plane of the other three";
    rejected(format!("{SURF}RECTANGLE 1 0 0 0 1 0 0 1 1 0 0 1 1").as_bytes(), "2:1", msg);
    rejected(format!("{SURF}RECTANGLE 1 0 0 0 1 0 0 1 1 0 0 1 0.002").as_bytes(), "2:1", msg);
    rejected(format!("{SURF}RECTANGLE 1 0 0 0 1e6 0 0 1e6 1e6 0 0 1e6 1e4").as_bytes(), "2:1", msg);
    // Within the tolerance (5e-4 < 2^-10) it is accepted.
    rendered(format!("RASTER 8 8 {SURF}RECTANGLE 1 0 0 0 1 0 0 1 1 0 0 1 0.0005").as_bytes(), &[], 8, 8);
    // The other ways a quadrilateral fails.
    rejected(
        format!("{SURF}RECTANGLE 1 0 0 0 1 1 0 1 0 0 0 1 0").as_bytes(),
        "2:1",
        "RECTANGLE is not convex: its corners must turn the same way (counter-clockwise seen from the front)",
    );
    rejected(
        format!("{SURF}RECTANGLE 1 0 0 0 1 1 1 2 2 2 3 3 3").as_bytes(),
        "2:1",
        "RECTANGLE is degenerate: its corners are collinear (zero area)",
    );
    rejected(
        format!("{SURF}RECTANGLE 1 4 4 4 4 4 4 4 4 4 4 4 4").as_bytes(),
        "2:1",
        "RECTANGLE is degenerate: its corners coincide",
    );
}

// ---------------------------------------------------------------------------
// 13-15: work without bound in the input

/// The stats line host-sim prints after a render.
fn stats_line(stderr: &str) -> &str {
    stderr.lines().find(|l| l.contains(" rays, ")).unwrap_or_else(|| panic!("no stats line in {stderr}"))
}

/// The number before `what` in the stats line.
fn stat(line: &str, what: &str) -> u64 {
    let before = &line[..line.find(what).unwrap_or_else(|| panic!("no {what:?} in {line}"))];
    before.split_whitespace().last().and_then(|n| n.trim_start_matches('(').parse().ok()).unwrap()
}

/// Row 13: RDEPTH 1000 between two perfect facing mirrors (reflectivity 1)
/// finishes in bounded time: every ray bounces exactly 1000 times. With
/// transparency 1 too, the ray tree doubles at each hit; the per-sample
/// limits cut it, and host-sim reports the cut branches.
#[test]
fn row13_rdepth_1000_between_facing_mirrors() {
    let mirror = "SURFACE 1 0.01 0.01 0.01 0.1 0.1 0.1 0 0 0 1 1 0\n";
    let half_mirror = "SURFACE 1 0.01 0.01 0.01 0.1 0.1 0.1 0 0 0 1 1 1\n";
    // Planes at z = ±1, 4000 wide: the widest ray (30° off the axis) drifts
    // 1.2 per bounce, so all 1000 bounces stay between them.
    let plane = |z: i32| format!("RECTANGLE 1 -2000 -2000 {z} 2000 -2000 {z} 2000 2000 {z} -2000 2000 {z}\n");
    let base = "RASTER 16 16 RDEPTH 1000 VIEWPOINT 0 0 0 ORIGIN 0 0 -1 LIGHT 1 0 0.5 0.5\n";
    let two = format!("{base}{mirror}{}{}", plane(-1), plane(1));
    let four = format!("{base}{half_mirror}{}{}{}{}", plane(-1), plane(1), plane(-3), plane(3));
    for (name, scene) in [("two mirrors", two), ("four half-mirrors", four)] {
        let started = Instant::now();
        let r = run(scene.as_bytes());
        let took = started.elapsed();
        assert_image(&r, 16, 16);
        let line = stats_line(&r.stderr);
        println!("{name}: {took:.2?}: {line}");
        assert!(took < Duration::from_secs(20), "{name}: {took:?}");
        let (rays, truncated) =
            (stat(line, " rays"), line.find("branches").map_or(0, |_| stat(line, " ray-tree branches")));
        if name == "two mirrors" {
            assert_eq!(rays, 256 * 1001, "{line}");
            assert_eq!(truncated, 0, "{line}");
        } else {
            assert_eq!(rays, 256 * 4096, "{line}");
            assert!(truncated > 0, "{line}");
        }
    }
}

/// Row 14: 100,000 small spheres in a 50×50×40 grid, 16×16 in the default
/// auto mode (which picks dda).
#[test]
fn row14_one_hundred_thousand_objects() {
    let mut text = String::from("RASTER 16 16 VIEWPOINT 80 70 120 ORIGIN 25 25 20 LIGHT 1 100 100 100\n");
    text.push_str(SURF);
    for i in 0..50 {
        for j in 0..50 {
            for k in 0..40 {
                text.push_str(&format!("SPHERE 1 0.3 {i} {j} {k}\n"));
            }
        }
    }
    let started = Instant::now();
    let r = run(text.as_bytes());
    let img = assert_image(&r, 16, 16);
    let line = stats_line(&r.stderr);
    println!("100,000 spheres ({} bytes): {:.2?}: {line}", text.len(), started.elapsed());
    assert!(line.contains("(dda, "), "{line}");
    // The grid fills the middle of the view.
    assert_ne!(img.pixel(8, 8), [0, 0, 0]);
}

const MB50: usize = 50 << 20;

/// A small valid scene (an 8×6 image), to follow 50 MB of filler.
fn tail() -> String {
    format!("RASTER 8 6 GAMMA 1 VIEWPOINT 0 0 10 SPHERE 1 2 0 0 0 LIGHT 1 0 0 10 {SURF}")
}

/// Row 15a: a 50 MB block comment (full of `/*`, `//`, `*` and `/`, but no
/// `*/`) before a scene: read in linear time; the scene after it counts.
#[test]
fn row15_fifty_megabyte_comment() {
    let line = "  /* not nested // nor a line comment ** / * / /\t unicode: ✓ é\r\n";
    let mut text = String::with_capacity(MB50 + 200);
    text.push_str("/*");
    while text.len() < MB50 {
        text.push_str(line);
    }
    text.push_str("*/ ");
    text.push_str(&tail());
    let started = Instant::now();
    let r = run(text.as_bytes());
    let img = assert_image(&r, 8, 6);
    let took = started.elapsed();
    println!("{} byte comment: {took:.2?}", text.len());
    assert_ne!(img.pixel(4, 3), [0, 0, 0], "the sphere after the comment is drawn");
    assert!(took < Duration::from_secs(20), "{took:?}");
    // The same comment left open: an error at line 1, column 1, and nothing
    // rendered from the scene inside it.
    text.truncate(text.len() - tail().len() - 3);
    text.insert_str(0, "RASTER 8 6\n");
    let started = Instant::now();
    rejected(text.as_bytes(), "2:1", "unterminated comment: this `/*` is never closed");
    println!("unterminated: {:.2?}", started.elapsed());
}

/// Row 15b: 50 MB of whitespace and line comments (about 1.9 million lines),
/// then a scene: it renders; and an error after the filler is placed at the
/// right line and column.
#[test]
fn row15_fifty_megabytes_of_whitespace_and_line_comments() {
    let lines = ["// a line comment /* that opens nothing\n", " \t \r\n", "\n", "\t\t\t// x */ y\n"];
    let mut text = String::with_capacity(MB50 + 200);
    let mut n = 0usize;
    while text.len() < MB50 {
        text.push_str(lines[n % lines.len()]);
        n += 1;
    }
    text.push_str(&tail());
    let started = Instant::now();
    let r = run(text.as_bytes());
    let img = assert_image(&r, 8, 6);
    let took = started.elapsed();
    println!("{} bytes, {n} lines of filler: {took:.2?}", text.len());
    assert_ne!(img.pixel(4, 3), [0, 0, 0]);
    assert!(took < Duration::from_secs(20), "{took:?}");
    // An unknown word after the scene (which ends with a newline), on the
    // line after.
    text.push_str("\n   BOGUS");
    let at = format!("{}:4", n + 3);
    rejected(text.as_bytes(), &at, "unknown keyword `BOGUS`");
}

/// Row 15c: one 50 MB token: a number with 50 MB of zeros is still a number
/// (RASTER width 8, a fraction 0.5000…).
#[test]
fn row15_fifty_megabyte_number() {
    let zeros = "0".repeat(MB50 / 2);
    let text = format!("RASTER {zeros}8 6 GAMMA 1 SPHERE 1 2.{zeros} 0 0 0 LIGHT 1 0 0 10 {SURF}");
    let started = Instant::now();
    let img = assert_image(&run(text.as_bytes()), 8, 6);
    println!("{} byte numbers: {:.2?}", text.len(), started.elapsed());
    assert_ne!(img.pixel(4, 3), [0, 0, 0]);
}

// ---------------------------------------------------------------------------
// 16-17

/// Row 16: a file that is not UTF-8 is an error at the first bad byte, in a
/// comment as anywhere else (the format requires UTF-8 throughout).
#[test]
fn row16_non_utf8_bytes() {
    let msg = "the file is not valid UTF-8 (invalid byte here)";
    // Latin-1 é in a comment; the column counts characters before it.
    rejected(b"RDEPTH 1\n// caf\xe9 au lait\n", "2:7", msg);
    rejected(b"/* \xc3\xa9t\xe9 */", "1:6", msg);
    // In a keyword's place.
    rejected(b"RDEPTH 1\n\xff\xfeSPHERE 1 1 0 0 0", "2:1", msg);
    rejected(b"RDEPTH 1\n  SPH\x80RE 1 1 0 0 0", "2:6", msg);
    // A number's place; a truncated multi-byte character at the very end.
    rejected(b"RASTER 8 \xc0\xaf", "1:10", msg);
    rejected(b"RDEPTH 1 // \xe2\x9c", "1:13", msg);
    // An encoded surrogate (CESU-8) is not UTF-8 either.
    rejected(b"\xed\xa0\x80", "1:1", msg);
}

/// Row 17: an object that uses a surface no SURFACE defines is an error at
/// the object's keyword, for every kind of object.
#[test]
fn row17_undefined_surface() {
    let undefined = |kw: &str, n: &str| format!("{kw} uses surface {n}, which is never defined");
    rejected(b"SPHERE 4 1 0 0 0", "1:1", &undefined("SPHERE", "4"));
    rejected(format!("{SURF}\n  SPHERE 2 1 0 0 0").as_bytes(), "3:3", &undefined("SPHERE", "2"));
    rejected(format!("{SURF}BOX 1000000 0 0 0 1 1 1").as_bytes(), "2:1", &undefined("BOX", "1000000"));
    rejected(b"TRIANGLE 0 0 0 0 1 0 0 0 1 0", "1:1", &undefined("TRIANGLE", "0"));
    rejected(b"RECTANGLE 7 0 0 0 1 0 0 1 1 0 0 1 0", "1:1", &undefined("RECTANGLE", "7"));
    rejected(b"SUPERQUADRIC 3 4 0 0 0 1 1 1", "1:1", &undefined("SUPERQUADRIC", "3"));
    // Defined later in the file is fine; each bad object is reported.
    let r = run(b"SPHERE 5 1 0 0 0\nSPHERE 6 1 0 0 0\nSPHERE 5 1 3 0 0");
    assert_eq!(r.code, 2);
    for want in ["scene.txt:1:1: SPHERE uses surface 5", "scene.txt:2:1: SPHERE uses surface 6", "3 error(s)"] {
        assert!(r.stderr.contains(want), "{want:?} in {}", r.stderr);
    }
    rendered(b"RASTER 4 4 SPHERE 9 1 0 0 0 SURFACE 9 0 0 0 0 0 0 0 0 0 0 0 0", &[], 4, 4);
}

// ---------------------------------------------------------------------------
// 18: the command line's files

fn small_scene(dir: &Path) -> (PathBuf, String) {
    let scene = dir.join("s.txt");
    let text = format!("RASTER 4 4 {SURF} SPHERE 1 1 0 0 0");
    std::fs::write(&scene, &text).unwrap();
    (scene, text)
}

/// Row 18a: output into a directory that does not exist: exit 1, the
/// directory is not created, no file is left anywhere.
#[test]
fn row18_output_to_a_missing_directory() {
    let dir = tempfile::tempdir().unwrap();
    let (scene, _) = small_scene(dir.path());
    for out in ["missing/o.png", "missing/deeper/o.png"] {
        let out = dir.path().join(out);
        let (code, err) = host_sim(&[scene.as_os_str(), out.as_os_str()]);
        assert_eq!(code, 1, "{err}");
        assert!(err.contains(&format!("host-sim: cannot write {}: ", out.display())), "{err}");
        assert_eq!(listing(dir.path()), ["s.txt"]);
    }
    // OUT naming a directory that exists: nothing replaces it.
    let sub = dir.path().join("sub");
    std::fs::create_dir(&sub).unwrap();
    let (code, err) = host_sim(&[scene.as_os_str(), sub.as_os_str()]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("cannot write"), "{err}");
    assert!(sub.is_dir());
    assert_eq!(listing(dir.path()), ["s.txt", "sub"]);
    assert!(listing(&sub).is_empty());
}

/// Whether this process can create files in a directory without write
/// permission (root, or CAP_DAC_OVERRIDE).
fn permissions_are_ignored(dir: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    let probe = dir.join("probe");
    std::fs::create_dir(&probe).unwrap();
    std::fs::set_permissions(&probe, std::fs::Permissions::from_mode(0o555)).unwrap();
    let ignored = std::fs::write(probe.join("x"), b"x").is_ok();
    std::fs::set_permissions(&probe, std::fs::Permissions::from_mode(0o755)).unwrap();
    std::fs::remove_dir_all(&probe).unwrap();
    ignored
}

/// Row 18b: output to an unwritable place: exit 1, nothing written.
/// Without root, a directory of mode 0555; as root (permission bits do not
/// stop writes) that case is skipped, and these stand in for it: a path
/// whose parent is a regular file, and a path under /proc.
#[test]
fn row18_output_to_an_unwritable_path() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let (scene, _) = small_scene(dir.path());
    if permissions_are_ignored(dir.path()) {
        println!("running as root: the read-only directory case is skipped");
    } else {
        let ro = dir.path().join("ro");
        std::fs::create_dir(&ro).unwrap();
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
        let out = ro.join("o.png");
        let (code, err) = host_sim(&[scene.as_os_str(), out.as_os_str()]);
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
        assert_eq!(code, 1, "{err}");
        assert!(err.contains("cannot write") && err.contains("ermission denied"), "{err}");
        assert!(listing(&ro).is_empty());
        std::fs::remove_dir(&ro).unwrap();
    }
    // A read-only file is not replaced (even by root, and although the
    // image would go through a temporary file and a rename).
    let readonly = dir.path().join("readonly.png");
    std::fs::write(&readonly, b"keep").unwrap();
    std::fs::set_permissions(&readonly, std::fs::Permissions::from_mode(0o444)).unwrap();
    let (code, err) = host_sim(&[scene.as_os_str(), readonly.as_os_str()]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("the file is read-only"), "{err}");
    assert_eq!(std::fs::read(&readonly).unwrap(), b"keep");
    std::fs::remove_file(&readonly).unwrap();
    // The parent is a regular file (ENOTDIR, even for root).
    let out = scene.join("o.png");
    let (code, err) = host_sim(&[scene.as_os_str(), out.as_os_str()]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains(&format!("host-sim: cannot write {}: ", out.display())), "{err}");
    assert_eq!(listing(dir.path()), ["s.txt"]);
    // /proc takes no new files, even from root.
    let out = Path::new("/proc/octrace-hostile-test.png");
    let (code, err) = host_sim(&[scene.as_os_str(), out.as_os_str()]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("host-sim: cannot write /proc/octrace-hostile-test.png: "), "{err}");
    assert!(!out.exists());
    assert!(!listing(Path::new("/proc")).iter().any(|n| n.contains("octrace-hostile")));
}

/// Row 18c: a scene path that does not exist, or is a directory: exit 1.
#[test]
fn row18_scene_that_cannot_be_read() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.png");
    for scene in [dir.path().join("nope.txt"), dir.path().to_path_buf()] {
        let (code, err) = host_sim(&[scene.as_os_str(), out.as_os_str()]);
        assert_eq!(code, 1, "{err}");
        assert!(err.contains(&format!("host-sim: cannot read {}: ", scene.display())), "{err}");
        assert!(listing(dir.path()).is_empty());
    }
}

/// Row 18d: OUT naming the scene file (directly, through `..`, through a
/// symbolic link, or as the scene's IMAGEFILE) is refused: exit 2, the scene
/// unchanged.
#[test]
fn row18_output_equal_to_the_scene_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (scene, text) = small_scene(dir.path());
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    let link = dir.path().join("link.png");
    std::os::unix::fs::symlink(&scene, &link).unwrap();
    for out in [scene.clone(), dir.path().join("sub/../s.txt"), link.clone()] {
        let (code, err) = host_sim(&[scene.as_os_str(), out.as_os_str()]);
        assert_eq!(code, 2, "{}: {err}", out.display());
        // The scene is named, and the path that led to it.
        let named = format!("refusing to overwrite the scene file {}", scene.display());
        assert!(err.contains(&named), "{err}");
        assert_eq!(err.contains(&format!("(which {} names)", out.display())), out != scene, "{err}");
        assert_eq!(std::fs::read_to_string(&scene).unwrap(), text);
        assert_eq!(listing(dir.path()), ["link.png", "s.txt", "sub"]);
    }
    // IMAGEFILE naming the scene itself.
    let text = format!("RASTER 4 4 IMAGEFILE \"{}\" {SURF}", scene.display());
    std::fs::write(&scene, &text).unwrap();
    let (code, err) = host_sim(&[scene.as_os_str()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("refusing to overwrite the scene file"), "{err}");
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), text);
    assert_eq!(listing(dir.path()), ["link.png", "s.txt", "sub"]);
}

/// Row 18e: OUT a pipe (or a device: `/dev/null`, `/dev/stdout`) is
/// written into, as a shell's `>` would; a temporary file renamed over it
/// would replace the node (as root, `/dev/null` itself).
#[test]
fn row18_output_to_a_pipe_is_written_into() {
    use std::os::unix::fs::FileTypeExt;
    let dir = tempfile::tempdir().unwrap();
    let (scene, _) = small_scene(dir.path());
    let fifo = dir.path().join("o.png");
    assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(fifo).unwrap())
    };
    let (code, err) = host_sim(&[scene.as_os_str(), fifo.as_os_str(), "-q".as_ref()]);
    assert_eq!(code, 0, "{err}");
    let png = reader.join().unwrap();
    assert_eq!(octrace_images::formats::read(&png).unwrap().to_rgb().width, 4, "a PNG came through the pipe");
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo(), "still a pipe");
    assert_eq!(listing(dir.path()), ["o.png", "s.txt"]);
}

/// Row 18e, too: OUT a symbolic link is written through, as a shell's `>`
/// would: the file it names (relative to the link, through a chain of
/// links, or not there yet) gets the image, the link stays a link.
#[test]
fn row18_output_through_a_symlink_writes_its_file() {
    let dir = tempfile::tempdir().unwrap();
    let (scene, _) = small_scene(dir.path());
    std::fs::create_dir(dir.path().join("images")).unwrap();
    std::fs::write(dir.path().join("images/real.png"), b"old").unwrap();
    std::os::unix::fs::symlink("images/real.png", dir.path().join("link.png")).unwrap();
    std::os::unix::fs::symlink("link.png", dir.path().join("chain.png")).unwrap();
    std::os::unix::fs::symlink("images/new.png", dir.path().join("dangling.png")).unwrap();
    for (out, file) in [("chain.png", "images/real.png"), ("dangling.png", "images/new.png")] {
        let (code, err) = host_sim(&[scene.as_os_str(), dir.path().join(out).as_os_str(), "-q".as_ref()]);
        assert_eq!(code, 0, "{out}: {err}");
        let png = std::fs::read(dir.path().join(file)).unwrap();
        assert_eq!(octrace_images::formats::read(&png).unwrap().to_rgb().width, 4, "{out}: the image in {file}");
    }
    for link in ["link.png", "chain.png", "dangling.png"] {
        assert!(std::fs::symlink_metadata(dir.path().join(link)).unwrap().file_type().is_symlink(), "{link}");
    }
    assert_eq!(listing(&dir.path().join("images")), ["new.png", "real.png"]);
}

/// Row 18f: frame files (`f%d.png`) are each guarded as a still's OUT: the
/// scene, a read-only file and a directory are refused before anything is
/// rendered, and a failed run leaves the files that were there before.
#[test]
fn row18_frame_files_are_guarded_as_a_stills_file() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let text = format!("FRAMES 3 RASTER 4 4 {SURF} SPHERE 1 1 0 0 0");
    // A scene named as its frame 1 would be.
    let scene = dir.path().join("f1.png");
    std::fs::write(&scene, &text).unwrap();
    let pattern = dir.path().join("f%d.png");
    let (code, err) = host_sim(&[scene.as_os_str(), pattern.as_os_str()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains(&format!("refusing to overwrite the scene file {}", scene.display())), "{err}");
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), text);
    assert_eq!(listing(dir.path()), ["f1.png"]);
    // Earlier frames, one read-only, then one a directory.
    let scene = dir.path().join("s.txt");
    std::fs::write(&scene, &text).unwrap();
    std::fs::write(dir.path().join("f0.png"), b"old 0").unwrap();
    std::fs::set_permissions(dir.path().join("f1.png"), std::fs::Permissions::from_mode(0o444)).unwrap();
    let (code, err) = host_sim(&[scene.as_os_str(), pattern.as_os_str()]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!("cannot write {}: the file is read-only", dir.path().join("f1.png").display())),
        "{err}"
    );
    std::fs::remove_file(dir.path().join("f1.png")).unwrap();
    std::fs::create_dir(dir.path().join("f2.png")).unwrap();
    let (code, err) = host_sim(&[scene.as_os_str(), pattern.as_os_str()]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains(&format!("cannot write {}: not a file", dir.path().join("f2.png").display())), "{err}");
    assert_eq!(std::fs::read(dir.path().join("f0.png")).unwrap(), b"old 0", "the earlier frame is kept");
    assert_eq!(listing(dir.path()), ["f0.png", "f2.png", "s.txt"]);
}

/// Row 18g: an IMAGEFILE name is shown with its control characters
/// escaped, and one longer than a path can be is refused unprinted.
#[test]
fn row18_imagefile_names_cannot_drive_the_terminal() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.txt");
    let name = dir.path().join("\u{1b}[2Jx.png");
    std::fs::write(&scene, format!("RASTER 4 4 IMAGEFILE \"{}\" {SURF} SPHERE 1 1 0 0 0", name.display())).unwrap();
    let (code, err) = host_sim(&[scene.as_os_str()]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains('\u{1b}') && err.contains("\\u{1b}[2Jx.png"), "{err}");
    assert!(name.exists());
    std::fs::write(&scene, format!("RASTER 4 4 IMAGEFILE {} {SURF}", "a".repeat(100_000))).unwrap();
    let (code, err) = host_sim(&[scene.as_os_str()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.len() < 300 && err.contains("names a path of 100000 bytes"), "{err}");
    // The scene file's own name, in its errors and a still's and an
    // animation's summary line.
    for text in ["RASTER 4 4 SPHERE", "FRAMES 2 RASTER 4 4 SPHERE"] {
        let scene = dir.path().join("\u{1b}[31ms.txt");
        std::fs::write(&scene, text).unwrap();
        let (code, err) = host_sim(&[scene.as_os_str(), dir.path().join("o.gif").as_os_str()]);
        assert_eq!(code, 2, "{err}");
        assert!(!err.contains('\u{1b}') && err.contains("\\u{1b}[31ms.txt:1:"), "{err}");
    }
}

/// Row 18h: `merge` refuses to write over one of the files it merges.
#[test]
fn row18_merge_does_not_write_over_its_parts() {
    let dir = tempfile::tempdir().unwrap();
    let (scene, _) = small_scene(dir.path());
    let parts: Vec<_> = (1..=2).map(|i| dir.path().join(format!("p{i}.png"))).collect();
    for (i, part) in parts.iter().enumerate() {
        let spec = format!("{}/2", i + 1);
        let (code, err) = host_sim(&[scene.as_os_str(), part.as_os_str(), "--part".as_ref(), spec.as_ref()]);
        assert_eq!(code, 0, "{err}");
    }
    let before = std::fs::read(&parts[0]).unwrap();
    let (code, err) = host_sim(&["merge".as_ref(), parts[0].as_os_str(), parts[0].as_os_str(), parts[1].as_os_str()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("refusing to write over") && err.contains("nothing written"), "{err}");
    assert_eq!(std::fs::read(&parts[0]).unwrap(), before);
}

/// Row 18i: what a still's command cannot do with an animation is refused
/// (exit 2, nothing written): `--frame K` to a frame pattern, `convert` of
/// an animated PNG (it would keep the first frame only); and an empty
/// IMAGEFILE is the scene's error.
#[test]
fn row18_still_commands_refuse_what_is_an_animation() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("a.txt");
    std::fs::write(&scene, format!("FRAMES 3 RASTER 4 4 {SURF} SPHERE 1 1 0 0 0")).unwrap();
    let pattern = dir.path().join("f%02d.png");
    let (code, err) = host_sim(&[scene.as_os_str(), pattern.as_os_str(), "--frame".as_ref(), "1".as_ref()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--frame 1 writes one still image"), "{err}");
    let apng = dir.path().join("a.png");
    let (code, err) = host_sim(&[scene.as_os_str(), apng.as_os_str(), "-q".as_ref()]);
    assert_eq!(code, 0, "{err}");
    let out = dir.path().join("b.tga");
    let (code, err) = host_sim(&["convert".as_ref(), apng.as_os_str(), out.as_os_str()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("an animated PNG of 3 frames"), "{err}");
    std::fs::write(&scene, format!("RASTER 4 4 IMAGEFILE \"\" {SURF}")).unwrap();
    let (code, err) = host_sim(&[scene.as_os_str()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("a.txt:1:22: IMAGEFILE names no file"), "{err}");
    assert_eq!(listing(dir.path()), ["a.png", "a.txt"]);
}

/// Row 19: every line's error in one run. After an error the parser
/// resynchronises at the next statement (a keyword, or a word opening a
/// line), so no line's error hides behind the one before.
#[test]
fn row19_every_lines_error_is_reported() {
    let at = |r: &Run| -> Vec<String> {
        r.stderr
            .lines()
            .filter_map(|l| l.split_once("scene.txt:").map(|(_, rest)| rest))
            .map(|l| l.split(": ").next().unwrap().into())
            .collect()
    };
    let r = run(b"x\nx\nx\nx\nx\n");
    assert_rejected(&r, "5:1", "unknown keyword `x`");
    assert_eq!(at(&r), ["1:1", "2:1", "3:1", "4:1", "5:1"], "{}", r.stderr);
    assert!(r.stderr.contains("host-sim: 5 error(s) in "), "{}", r.stderr);
    // A statement cut short by a keyword on the next line, a bad number, a
    // bad word opening a line, an unterminated comment.
    let r = run(b"SPHERE 1 1 0 0\nRDEPTH 2 x\nLIGHT 1 0 5 q\nfoo 1 2\n  3 4\nRDEPTH 3\n/* open\nx\n");
    assert_rejected(&r, "7:1", "unterminated comment");
    assert_eq!(at(&r), ["2:1", "2:10", "3:13", "4:1", "6:1", "7:1"], "{}", r.stderr);
}
