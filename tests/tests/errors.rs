//! Every error kind of the scene format (`docs/scene-format.md`) through
//! `host-sim`, as a user meets it: the message with file:line:col, a non-zero
//! exit code, and no output file. Also the failures of the command line: I/O,
//! and output files it would not write.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

const SURF: &str = "SURFACE 1 0.1 0.1 0.1 0.5 0.5 0.5 1 1 1 10 0 0\n";

struct Run {
    code: i32,
    stderr: String,
    out: PathBuf,
    _dir: tempfile::TempDir,
}

/// Runs `host-sim scene.txt out.png` on `scene` (bytes) in a fresh directory.
fn run_bytes(scene: &[u8]) -> Run {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.txt");
    std::fs::write(&path, scene).unwrap();
    let out = dir.path().join("out.png");
    let mut stderr = Vec::new();
    let code =
        host_sim::cli::run(["host-sim".as_ref(), path.as_os_str(), out.as_os_str()], &mut std::io::sink(), &mut stderr);
    Run { code, stderr: String::from_utf8_lossy(&stderr).into_owned(), out, _dir: dir }
}

fn no_files_but_the_scene(dir: &Path) -> bool {
    std::fs::read_dir(dir).unwrap().count() == 1
}

/// The scene is rejected with `message` at `line:col`, exit code 2, and
/// nothing is written.
fn rejected(scene: &str, at: &str, message: &str) {
    rejected_bytes(scene.as_bytes(), at, message)
}

fn rejected_bytes(scene: &[u8], at: &str, message: &str) {
    let r = run_bytes(scene);
    assert_eq!(r.code, 2, "{}", r.stderr);
    let want = format!("scene.txt:{at}: {message}");
    assert!(r.stderr.contains(&want), "want {want:?} in:\n{}", r.stderr);
    assert!(!r.out.exists(), "an output file was written");
    assert!(no_files_but_the_scene(r._dir.path()), "a temporary file was left behind");
}

#[test]
fn unknown_keyword() {
    rejected("SPHERE 1 1 0 0 0\nCUBE 1 2", "2:1", "unknown keyword `CUBE`");
}

#[test]
fn missing_and_malformed_numbers() {
    rejected("LIGHT 1 0 0", "1:12", "expected a number for LIGHT z, found the end of the file");
    rejected("GAMMA nan", "1:7", "expected a number for GAMMA value, found `nan`");
    rejected("GAMMA inf", "1:7", "expected a number for GAMMA value, found `inf`");
    rejected("GAMMA 0x10", "1:7", "expected a number for GAMMA value, found `0x10`");
    rejected("VIEWPOINT 1 2 three", "1:15", "expected a number for VIEWPOINT z, found `three`");
}

#[test]
fn a_file_that_ends_inside_a_statement_points_after_its_last_token() {
    let end = "expected a number for SPHERE z, found the end of the file";
    rejected(&format!("{SURF}SPHERE 1 1 0 0\n"), "2:15", end);
    rejected(&format!("{SURF}SPHERE 1 1 0 0 // z is missing\n\n\n"), "2:15", end);
    rejected("RDEPTH 2\n  IMAGEFILE\n", "2:12", "expected IMAGEFILE file name, found the end of the file");
    rejected("RDEPTH 2\nIMAGEFILE \"out.png\n", "2:11", "unterminated string: this `\"` is never closed");
}

#[test]
fn non_integer_where_an_integer_is_required() {
    rejected("RDEPTH 2.5", "1:8", "expected an integer for RDEPTH depth, found `2.5`");
    rejected("RASTER 64 4e1", "1:11", "expected an integer for RASTER height, found `4e1`");
}

#[test]
fn values_out_of_range() {
    rejected(&format!("{SURF}SPHERE 1 -1 0 0 0"), "2:10", "SPHERE radius must be > 0, found -1");
    rejected("VIEWPOINT 0 0 2e6", "1:15", "VIEWPOINT z must be at most 1e6 in magnitude, found 2e6");
    rejected("SAMPLES 0", "1:9", "SAMPLES count must be an integer from 1 to 16, found 0");
    rejected("BACKGROUND 0 0 -0.1", "1:16", "BACKGROUND blue must be between 0 and 1, found -0.1");
}

#[test]
fn repeated_parameter_names_both_lines() {
    rejected("RASTER 10 10\n\nRASTER 20 20", "3:1", "RASTER is given twice (first on line 1)");
}

#[test]
fn undefined_and_repeated_surfaces() {
    rejected("SPHERE 4 1 0 0 0", "1:1", "SPHERE uses surface 4, which is never defined");
    rejected(&format!("{SURF}\n{SURF}"), "3:1", "SURFACE 1 is defined twice (first on line 1)");
}

#[test]
fn degenerate_and_non_planar_shapes() {
    rejected(&format!("{SURF}TRIANGLE 1 0 0 0 1 1 1 3 3 3"), "2:1", "TRIANGLE is degenerate");
    rejected(&format!("{SURF}RECTANGLE 1 0 0 0 1 0 0 1 1 1 0 1 0"), "2:1", "RECTANGLE is not planar");
    rejected(&format!("{SURF}RECTANGLE 1 0 0 0 1 1 0 1 0 0 0 1 0"), "2:1", "RECTANGLE is not convex");
}

#[test]
fn patches_need_enough_control_points() {
    rejected(
        &format!("{SURF}BSPLINE 1 3 2 2 4 4  0 0 0  1 0 0  0 1 0  1 1 0"),
        "2:1",
        "BSPLINE of order 3 needs at least 3 control points along each side, found 2 × 2",
    );
}

#[test]
fn a_shape_too_small_for_the_scene_is_named() {
    // A scene a million units across resolves about 2^-29 of that (0.002).
    let wide = "LIGHT 1 -500000 0 0 LIGHT 1 500000 0 0\n";
    rejected(
        &format!("{wide}{SURF}BOX 1 0 0 0 0.0001 0.0001 0.0001"),
        "3:1",
        "BOX is too small to represent next to the rest of the scene \
         (sizes below about 2^-29 of the scene's extent round to 0 in fixed point)",
    );
}

#[test]
fn bad_cameras() {
    rejected("ORIGIN 0 0 10", "1:1", "VIEWPOINT equals ORIGIN");
    rejected("VIEWPOINT 0 5 0\nUPVECTOR 0 -2 0", "2:1", "UPVECTOR is zero or parallel to the view direction");
}

#[test]
fn unterminated_comment_names_its_opening() {
    rejected("RDEPTH 1\n  /* a comment\n that never ends", "2:3", "unterminated comment");
}

#[test]
fn invalid_utf8() {
    rejected_bytes(b"RDEPTH 1\nIMAGEFILE caf\xe9.png", "2:14", "the file is not valid UTF-8");
}

#[test]
fn capacity_names_the_limit_and_that_host_sim_holds_no_more() {
    let lights: String = (0..4097).map(|i| format!("LIGHT 1 {i} 0 0\n")).collect();
    rejected(
        &lights,
        "4097:1",
        "too many lights: the capacity profile Host holds 4096 and the scene needs 4097, \
         the most octrace's desktop build holds: split the scene or simplify it",
    );
}

#[test]
fn several_errors_are_all_reported() {
    let r = run_bytes(b"RDEPTH x\nGAMMA -1\nFOO\n");
    assert_eq!(r.code, 2);
    for want in ["scene.txt:1:8:", "scene.txt:2:7:", "scene.txt:3:1:", "3 error(s)"] {
        assert!(r.stderr.contains(want), "{want:?} in {}", r.stderr);
    }
}

#[test]
fn a_valid_scene_renders() {
    let r = run_bytes(format!("RASTER 8 6 {SURF} SPHERE 1 1 0 0 0 LIGHT 10 0 0 10").as_bytes());
    assert_eq!(r.code, 0, "{}", r.stderr);
    let img = octrace_images::formats::read(&std::fs::read(&r.out).unwrap()).unwrap();
    assert_eq!((img.width(), img.height()), (8, 6));
}

/// Runs host-sim with `args`; returns the exit code and stdout + stderr.
fn run_args(args: &[&std::ffi::OsStr]) -> (i32, String) {
    let (mut stdout, mut stderr) = (Vec::new(), Vec::new());
    let mut all = vec![std::ffi::OsStr::new("host-sim")];
    all.extend_from_slice(args);
    let code = host_sim::cli::run(all, &mut stdout, &mut stderr);
    stdout.extend(stderr);
    (code, String::from_utf8_lossy(&stdout).into_owned())
}

#[test]
fn missing_scene_file_is_an_io_error() {
    let dir = tempfile::tempdir().unwrap();
    let (code, err) = run_args(&[dir.path().join("nope.txt").as_os_str(), dir.path().join("o.png").as_os_str()]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("cannot read"), "{err}");
}

#[test]
fn output_to_a_missing_directory_fails_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.txt");
    std::fs::write(&scene, format!("RASTER 4 4 {SURF} SPHERE 1 1 0 0 0")).unwrap();
    let out = dir.path().join("missing/dir/o.png");
    let (code, err) = run_args(&[scene.as_os_str(), out.as_os_str()]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("cannot write"), "{err}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn output_equal_to_the_scene_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.txt");
    let text = format!("RASTER 4 4 {SURF} SPHERE 1 1 0 0 0");
    std::fs::write(&scene, &text).unwrap();
    let (code, err) = run_args(&[scene.as_os_str(), scene.as_os_str()]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), text);
}

/// A scene that renders, in `dir`.
fn small_scene(dir: &Path) -> PathBuf {
    let scene = dir.join("s.txt");
    std::fs::write(&scene, format!("RASTER 4 4 {SURF} SPHERE 1 1 0 0 0")).unwrap();
    scene
}

#[test]
fn an_output_extension_it_does_not_write_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path());
    for name in ["out.bmp", "out.png.jpg", "out.PNGX"] {
        let out = dir.path().join(name);
        let (code, err) = run_args(&[scene.as_os_str(), out.as_os_str()]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(&format!("host-sim: {}: `.", out.display())), "{err}");
        assert!(err.contains("png, tga, ras") && err.contains("--format"), "{err}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "{name}: a file was written");
    }
    // The same through IMAGEFILE, at its file name, and for `convert`.
    let imagefile = dir.path().join("i.txt");
    std::fs::write(&imagefile, format!("{SURF}\n IMAGEFILE \"{}\"", dir.path().join("x.gif").display())).unwrap();
    let (code, err) = run_args(&[imagefile.as_os_str()]);
    assert_eq!(
        (
            code,
            err.contains(&format!(
                "i.txt:3:12: IMAGEFILE {}: `.gif` is not a format host-sim writes a still image in (a GIF holds a whole \
                 animation: a scene with FRAMES, rendered without --frame, to one file)",
                dir.path().join("x.gif").display()
            ))
        ),
        (2, true),
        "{err}"
    );
    // An animation's IMAGEFILE names its GIF: a frame asked for is no
    // error of the scene's.
    std::fs::write(&imagefile, format!("FRAMES 2 {SURF}\n IMAGEFILE \"{}\"", dir.path().join("x.gif").display()))
        .unwrap();
    let (code, err) = run_args(&[imagefile.as_os_str(), "--frame".as_ref(), "1".as_ref()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.starts_with("host-sim: ") && err.contains("--frame 1 writes one still image: give OUT"), "{err}");
    let png = dir.path().join("a.png");
    assert_eq!(run_args(&[scene.as_os_str(), png.as_os_str()]).0, 0);
    let gif = dir.path().join("a.gif");
    let (code, err) = run_args(&["convert".as_ref(), png.as_os_str(), gif.as_os_str()]);
    assert_eq!((code, err.contains("--format")), (2, true), "{err}");
    assert!(!gif.exists());
}

#[test]
fn the_formats_it_writes_are_told_by_extension_or_format() {
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path());
    // (file name, --format, the file's first bytes)
    let png = b"\x89PNG".as_slice();
    let ras = b"\x59\xa6\x6a\x95".as_slice();
    let cases: [(&str, Option<&str>, &[u8]); 5] = [
        ("a.PNG", None, png),
        ("b.Ras", None, ras),
        ("no-extension", None, png),
        ("c.bmp", Some("png"), png),
        ("d.img", Some("ras"), ras),
    ];
    for (name, format, magic) in cases {
        let out = dir.path().join(name);
        let mut args = vec![scene.as_os_str(), out.as_os_str()];
        if let Some(f) = format {
            args.extend([OsStr::new("--format"), OsStr::new(f)]);
        }
        let (code, err) = run_args(&args);
        assert_eq!(code, 0, "{name}: {err}");
        let bytes = std::fs::read(&out).unwrap();
        assert!(bytes.starts_with(magic), "{name}: {:?}", &bytes[..4]);
        let image = octrace_images::formats::read(&bytes).unwrap();
        assert_eq!((image.width(), image.height()), (4, 4));
    }
    // --format may not contradict the extension: a Sun raster named .png
    // would mislead whatever opens it. Refused, nothing written.
    let contradicted = dir.path().join("f.png");
    let (code, err) = run_args(&[scene.as_os_str(), contradicted.as_os_str(), "--format".as_ref(), "ras".as_ref()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--format ras: ") && err.contains("f.png names a PNG file; give OUT a .ras name"), "{err}");
    assert!(!contradicted.exists());
    // Targa has no magic number: read back, it is the same image as the PNG.
    let tga = dir.path().join("e.tga");
    assert_eq!(run_args(&[scene.as_os_str(), tga.as_os_str()]).0, 0);
    let from_png = octrace_images::formats::read(&std::fs::read(dir.path().join("a.PNG")).unwrap()).unwrap();
    assert_eq!(octrace_images::formats::read(&std::fs::read(&tga).unwrap()).unwrap(), from_png);
    assert!(!std::fs::read(&tga).unwrap().starts_with(png));
}

#[test]
fn options_that_would_do_nothing_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path());
    let out = dir.path().join("still.png");
    for (option, value) in [("--frame", Some("1")), ("--no-coherence", None)] {
        let mut args = vec![scene.as_os_str(), out.as_os_str(), option.as_ref()];
        args.extend(value.map(OsStr::new));
        let (code, err) = run_args(&args);
        assert_eq!(code, 2, "{option}: {err}");
        assert!(err.contains(&format!("{option}: ")) && err.contains("is no animation (it has no FRAMES)"), "{err}");
        assert!(!out.exists(), "{option}");
    }
    // Octree options where no octree is built.
    let args = [
        scene.as_os_str(),
        out.as_os_str(),
        "--accel".as_ref(),
        "naive".as_ref(),
        "--max-objects".as_ref(),
        "2".as_ref(),
    ];
    let (code, err) = run_args(&args);
    assert!(code == 2 && err.contains("--max-objects shapes the octree, and --accel naive builds none"), "{err}");
    // auto, which tests a scene of a handful of objects without one, the same.
    let (code, err) = run_args(&[scene.as_os_str(), out.as_os_str(), "--max-depth".as_ref(), "3".as_ref()]);
    assert!(code == 2 && err.contains("--max-depth shapes the octree, and --accel auto tests "), "{err}");
    assert!(err.contains(" objects without one (up to 16): give --accel octree or dda"), "{err}");
    // convert onto its own input: refused, the file as it was.
    let png = dir.path().join("a.png");
    assert_eq!(run_args(&[scene.as_os_str(), png.as_os_str()]).0, 0);
    let before = std::fs::read(&png).unwrap();
    let (code, err) = run_args(&["convert".as_ref(), png.as_os_str(), png.as_os_str()]);
    assert!(code == 2 && err.contains("convert: refusing to write over"), "{err}");
    assert_eq!(std::fs::read(&png).unwrap(), before);
}

#[test]
fn imagefile_is_the_default_output_and_no_output_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.txt");
    let out = dir.path().join("from-imagefile.png");
    std::fs::write(&scene, format!("RASTER 4 4 IMAGEFILE \"{}\" {SURF}", out.display())).unwrap();
    let (code, err) = run_args(&[scene.as_os_str()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.exists());
    std::fs::write(&scene, "RASTER 4 4").unwrap();
    let (code, err) = run_args(&[scene.as_os_str()]);
    assert_eq!(code, 2);
    assert!(err.contains("no output file"), "{err}");
}

#[test]
fn help_documents_every_option() {
    let (code, out) = run_args(&["--help".as_ref()]);
    assert_eq!(code, 0);
    for option in ["--size <WxH>", "--quiet", "Exit codes", "IMAGEFILE"] {
        assert!(out.contains(option), "{option} missing from --help:\n{out}");
    }
}
