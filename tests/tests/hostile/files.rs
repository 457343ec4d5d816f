//! Rows 15 to 19 of the hostile-input table: fifty megabytes of comment,
//! whitespace or number, bytes that are not UTF-8, an undefined surface, output
//! paths that cannot or must not be written, and every line's error reported.

use super::*;

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
    // `DIR/` where there is no DIR names a directory too (the rename said
    // "Not a directory").
    let slashed = format!("{}/nodir/", dir.path().display());
    let (code, err) = host_sim(&[scene.as_os_str(), slashed.as_ref()]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains(&format!("cannot write {slashed}: Is a directory")), "{err}");
    assert_eq!(listing(dir.path()), ["s.txt", "sub"]);
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

/// Row 18c: a scene path that does not exist, is a directory, or a device
/// without end (read up to host-sim's limit, not until memory runs out):
/// exit 1.
#[test]
fn row18_scene_that_cannot_be_read() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.png");
    let (code, err) = host_sim(&["/dev/zero".as_ref(), out.as_os_str()]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("host-sim: cannot read /dev/zero: it is larger than 256 MiB"), "{err}");
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
    // `/dev/stdout` when standard output is a pipe: its links end in
    // `pipe:[N]`, which names no path, and open(2) follows them.
    for out in ["/dev/stdout", "/proc/self/fd/1"] {
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_host-sim-cli"))
            .arg(&scene)
            .args([out, "-q"])
            .stdout(std::process::Stdio::piped())
            .output()
            .unwrap();
        assert!(run.status.success(), "{out}: {}", String::from_utf8_lossy(&run.stderr));
        assert_eq!(octrace_images::formats::read(&run.stdout).unwrap().to_rgb().width, 4, "{out}: a PNG on the pipe");
    }
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
