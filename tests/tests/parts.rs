//! Rows streamed to the file, and renders split into parts (`--part I/N`, `merge`): the streamed files equal
//! the whole image in every palette mode and format, merged parts equal one render byte for byte, `merge`
//! refuses every kind of misfit, `--part auto/N` reads the schedulers' variables, and the GNU parallel recipe
//! of docs/distributed.md runs as written.

use host_sim::{load_file, new_scene, render, Partition, RenderOptions};
use octrace_images::formats::{self, Image};
use octrace_images::palette::{self, PaletteMode};
use octrace_tests::scene_path;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

/// host-sim's command line as a program (`tests/src/bin/host-sim-cli.rs`).
const HOST_SIM: &str = env!("CARGO_BIN_EXE_host-sim-cli");

const SCHEDULER_VARIABLES: [&str; 3] = ["SLURM_ARRAY_TASK_ID", "SLURM_ARRAY_TASK_MIN", "JOB_COMPLETION_INDEX"];

/// Runs host-sim with `args` and the environment `env` (none of the schedulers' variables otherwise):
/// exit code and standard error.
fn host_sim(args: &[&OsStr], env: &[(&str, &str)]) -> (i32, String) {
    let mut command = Command::new(HOST_SIM);
    command.args(args);
    for name in SCHEDULER_VARIABLES {
        command.env_remove(name);
    }
    command.envs(env.iter().copied());
    let output = command.output().expect("host-sim-cli runs");
    (output.status.code().unwrap_or(-1), String::from_utf8_lossy(&output.stderr).into_owned())
}

fn ok(args: &[&OsStr]) {
    let (code, err) = host_sim(args, &[]);
    assert_eq!(code, 0, "host-sim {args:?}: {err}");
}

fn read(path: &Path) -> Image {
    formats::read(&std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())))
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The files in `dir`, sorted.
fn files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

#[test]
fn streamed_files_equal_the_whole_image_in_every_mode_and_format() {
    let dir = tempfile::tempdir().unwrap();
    let path = scene_path("fig5_1");
    let mut loaded = new_scene();
    load_file(&path, &mut loaded).unwrap();
    // Neither side a multiple of the 32-row bands and tiles.
    let (w, h) = (75, 70);
    let rendered = render(&mut loaded, &RenderOptions { size: Some((w, h)), ..Default::default() }).unwrap();
    let mut expected_files = Vec::new();
    for mode in PaletteMode::ALL {
        let expected = palette::apply(&rendered.image, &rendered.objects, mode);
        for (extension, threads, partition) in [("png", "3", "tiles"), ("tga", "1", "equal4"), ("ras", "2", "tiles")] {
            let name = format!("{}-{partition}.{extension}", mode.name());
            let out = dir.path().join(&name);
            ok(&[
                path.as_os_str(),
                out.as_os_str(),
                "--size".as_ref(),
                "75x70".as_ref(),
                "--palette".as_ref(),
                mode.name().as_ref(),
                "--threads".as_ref(),
                threads.as_ref(),
                "--partition".as_ref(),
                partition.as_ref(),
                "-q".as_ref(),
            ]);
            assert_eq!(read(&out), expected, "{name}");
            expected_files.push(name);
        }
    }
    // The spool files of the indexed modes are gone.
    expected_files.sort();
    assert_eq!(files(dir.path()), expected_files);
    // The library's equal4 is the thesis's four rectangles, streamed as one band.
    let equal4 = render(
        &mut loaded,
        &RenderOptions { size: Some((w, h)), threads: 3, partition: Partition::Equal4, ..Default::default() },
    );
    assert_eq!(equal4.unwrap().image, rendered.image);
}

/// The arguments that render `part` (`I/N` or `auto/N`) of `scene` at 40×30 into `out`.
fn part_args<'a>(scene: &'a Path, out: &'a Path, part: &'a str) -> Vec<&'a OsStr> {
    vec![
        scene.as_os_str(),
        out.as_os_str(),
        "--size".as_ref(),
        "40x30".as_ref(),
        "--part".as_ref(),
        part.as_ref(),
        "-q".as_ref(),
    ]
}

/// Renders `parts` (I/N strings) of `scene` at 40×30 into `dir`, with `extra` arguments; the part files.
fn render_parts(dir: &Path, scene: &Path, parts: &[&str], extension: &str, extra: &[&str]) -> Vec<PathBuf> {
    parts
        .iter()
        .map(|part| {
            let out = dir.join(format!("part-{}.{extension}", part.replace('/', "of")));
            let mut args = part_args(scene, &out, part);
            args.extend(extra.iter().map(OsStr::new));
            ok(&args);
            out
        })
        .collect()
}

#[test]
fn merged_parts_are_one_render_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let path = scene_path("fig5_1");
    for mode in ["none", "dither", "coarse", "gray"] {
        for extension in ["png", "tga"] {
            let whole = dir.path().join(format!("whole-{mode}.png"));
            ok(&[
                path.as_os_str(),
                whole.as_os_str(),
                "--size".as_ref(),
                "40x30".as_ref(),
                "--palette".as_ref(),
                mode.as_ref(),
                "-q".as_ref(),
            ]);
            let sub = dir.path().join(format!("{mode}-{extension}"));
            std::fs::create_dir(&sub).unwrap();
            let mut parts =
                render_parts(&sub, &path, &["3/3", "1/3", "2/3"], extension, &["--palette", mode, "--threads", "2"]);
            let part = read(&parts[1]);
            assert_eq!((part.width(), part.height()), (40, 10), "a part is an image of its own");
            parts.reverse();
            let merged = dir.path().join(format!("merged-{mode}-{extension}.png"));
            let mut args = vec!["merge".as_ref(), merged.as_os_str()];
            args.extend(parts.iter().map(|p| p.as_os_str()));
            ok(&args);
            assert_eq!(std::fs::read(&merged).unwrap(), std::fs::read(&whole).unwrap(), "{mode}, {extension} parts");
        }
    }
    // Bands of different N fit together when their rows do; merge writes any format.
    let sub = dir.path().join("mixed");
    std::fs::create_dir(&sub).unwrap();
    let parts = render_parts(&sub, &path, &["1/2", "3/4", "4/4"], "png", &[]);
    let merged = dir.path().join("mixed.ras");
    let mut args = vec!["merge".as_ref(), merged.as_os_str()];
    args.extend(parts.iter().map(|p| p.as_os_str()));
    ok(&args);
    assert_eq!(read(&merged), read(&dir.path().join("whole-none.png")));
    // As many parts as rows.
    let sub = dir.path().join("rows");
    std::fs::create_dir(&sub).unwrap();
    let each: Vec<String> = (1..=30).map(|i| format!("{i}/30")).collect();
    let parts = render_parts(
        &sub,
        &path,
        &each.iter().map(String::as_str).collect::<Vec<_>>(),
        "tga",
        &["--palette", "coarse"],
    );
    let merged = dir.path().join("rows.png");
    let mut args = vec!["merge".as_ref(), merged.as_os_str()];
    args.extend(parts.iter().map(|p| p.as_os_str()));
    ok(&args);
    assert_eq!(std::fs::read(&merged).unwrap(), std::fs::read(dir.path().join("whole-coarse.png")).unwrap());
}

#[test]
fn a_part_converted_between_png_and_targa_still_merges() {
    let dir = tempfile::tempdir().unwrap();
    let path = scene_path("fig5_1");
    let parts = render_parts(dir.path(), &path, &["1/2", "2/2"], "png", &[]);
    let (whole, merged) = (dir.path().join("whole.png"), dir.path().join("merged.png"));
    ok(&[path.as_os_str(), whole.as_os_str(), "--size".as_ref(), "40x30".as_ref(), "-q".as_ref()]);
    let converted = dir.path().join("second.tga");
    ok(&["convert".as_ref(), parts[1].as_os_str(), converted.as_os_str()]);
    ok(&["merge".as_ref(), merged.as_os_str(), parts[0].as_os_str(), converted.as_os_str()]);
    assert_eq!(std::fs::read(&merged).unwrap(), std::fs::read(&whole).unwrap());
    // A Sun raster has no room for the part's metadata: said.
    let raster = dir.path().join("second.ras");
    let (code, err) = host_sim(&["convert".as_ref(), parts[1].as_os_str(), raster.as_os_str()], &[]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("which a Sun raster cannot"), "{err}");
}

#[test]
fn a_part_replaced_after_its_check_is_refused_not_merged() {
    let dir = tempfile::tempdir().unwrap();
    let parts = render_parts(dir.path(), &scene_path("fig5_1"), &["1/2", "2/2"], "png", &[]);
    let (checked, header) = host_sim::parts::check_parts(&parts).expect("two parts of one render");
    // Another job writes its part 1 over part 2 between the check and the merge.
    std::fs::copy(&parts[0], &parts[1]).unwrap();
    let mut out = Vec::new();
    let error = host_sim::parts::write_merged(&checked, &header, formats::Format::Png, &mut out)
        .expect_err("a part changed since its check");
    let want = format!("{}: changed while the parts were merged (it is no longer part 2/2", parts[1].display());
    assert!(error.to_string().starts_with(&want), "{error}");
}

#[test]
fn merge_refuses_parts_that_do_not_fit_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (fig5_1, fig5_2) = (scene_path("fig5_1"), scene_path("fig5_2"));
    let good = render_parts(dir.path(), &fig5_1, &["1/3", "2/3", "3/3"], "png", &[]);
    let half = render_parts(dir.path(), &fig5_1, &["2/2"], "png", &[]).remove(0);
    let other_dir = |name: &str| {
        let d = dir.path().join(name);
        std::fs::create_dir(&d).unwrap();
        d
    };
    let other_scene = render_parts(&other_dir("scene"), &fig5_2, &["2/3"], "png", &[]).remove(0);
    let other_palette = render_parts(&other_dir("palette"), &fig5_1, &["2/3"], "png", &["--palette", "gray"]).remove(0);
    let other_size = other_dir("size").join("part.png");
    ok(&[
        fig5_1.as_os_str(),
        other_size.as_os_str(),
        "--size".as_ref(),
        "40x33".as_ref(),
        "--part".as_ref(),
        "2/3".as_ref(),
        "-q".as_ref(),
    ]);
    let plain = dir.path().join("plain.png");
    ok(&[fig5_1.as_os_str(), plain.as_os_str(), "--size".as_ref(), "40x30".as_ref(), "-q".as_ref()]);
    // Bands of two frames of one animation: one scene, one size, two pictures.
    let animation = scene_path("anim_light");
    let frame_part = |frame: &str, part: &str| {
        render_parts(&other_dir(&format!("frame-{frame}")), &animation, &[part], "png", &["--frame", frame]).remove(0)
    };
    let (frame_3, frame_12) = (frame_part("3", "1/2"), frame_part("12", "2/2"));
    // A part whose header reads but whose pixels do not (a transfer cut short).
    let cut = dir.path().join("cut.png");
    let whole = std::fs::read(&good[2]).unwrap();
    std::fs::write(&cut, &whole[..whole.len() - 40]).unwrap();
    // Cut after its pixels: its IEND gone.
    let no_end = dir.path().join("no-end.png");
    std::fs::write(&no_end, &whole[..whole.len() - 12]).unwrap();
    let copy = dir.path().join("copy-of-2.png");
    std::fs::copy(&good[1], &copy).unwrap();
    let absent = dir.path().join("absent.png");

    let [one, two, three] = [&good[0], &good[1], &good[2]];
    let name = |p: &Path| p.display().to_string();
    let cases: Vec<(Vec<&PathBuf>, i32, Vec<String>)> = vec![
        (
            vec![one, three],
            2,
            vec!["rows 10..20 of the image are in no part (missing part 2/3)".into(), name(one), name(three)],
        ),
        (vec![two, three], 2, vec!["rows 0..10".into(), "missing part 1/3".into(), format!("before {}", name(two))]),
        (vec![one, two], 2, vec!["rows 20..30".into(), "missing part 3/3".into(), format!("after {}", name(two))]),
        (vec![one, two, &copy, three], 2, vec!["are the same band".into(), name(two), name(&copy)]),
        (
            vec![one, two, three, &half],
            2,
            vec!["are overlapping bands".into(), "part 2/2, rows 15..30".into(), name(&half)],
        ),
        (vec![one, &other_scene, three], 2, vec!["another scene".into(), name(&other_scene), name(one)]),
        (vec![one, &other_size, three], 2, vec!["another size (40×33, not 40×30)".into(), name(&other_size)]),
        (
            vec![one, &other_palette, three],
            2,
            vec!["another palette (--palette gray, not none)".into(), name(&other_palette)],
        ),
        (vec![one, &plain, three], 2, vec![format!("{}: not a part", name(&plain))]),
        (vec![one, two, &cut], 2, vec![format!("{}: not an image host-sim can merge: truncated", name(&cut))]),
        (vec![one, two, &no_end], 2, vec![format!("{}: not an image host-sim can merge", name(&no_end))]),
        (
            vec![&frame_3, &frame_12],
            2,
            vec!["another frame of the animation (frame 12, not frame 3)".into(), name(&frame_12), name(&frame_3)],
        ),
        (vec![one, two, three, &absent], 1, vec![name(&absent)]),
    ];
    let out = dir.path().join("merged.png");
    for (parts, expected_code, messages) in cases {
        let mut args = vec!["merge".as_ref(), out.as_os_str()];
        args.extend(parts.iter().map(|p| p.as_os_str()));
        let (code, err) = host_sim(&args, &[]);
        assert_eq!(code, expected_code, "{parts:?}: {err}");
        for message in messages {
            assert!(err.contains(&message), "{parts:?}: expected `{message}` in: {err}");
        }
        assert!(err.contains("nothing written"), "{err}");
        assert!(!out.exists(), "{parts:?}: a file was written");
    }
    // A tampered part: the image no longer matches its metadata.
    let bytes = std::fs::read(&good[0]).unwrap();
    let text = "rows=0..10 part=1/3";
    let at = bytes.windows(text.len()).position(|w| w == text.as_bytes()).expect("the metadata is in the PNG");
    let mut forged = bytes.clone();
    forged[at..at + text.len()].copy_from_slice(b"rows=0..15 part=1/2");
    let forged_path = dir.path().join("forged.png");
    std::fs::write(&forged_path, forged).unwrap();
    let (code, err) = host_sim(&["merge".as_ref(), out.as_os_str(), forged_path.as_os_str()], &[]);
    // The chunk's checksum no longer matches: the PNG is refused as malformed.
    assert_eq!(code, 2, "{err}");
    assert!(err.contains(&name(&forged_path)), "{err}");
    assert!(!out.exists());
    // With the three good parts, it merges.
    let mut args = vec!["merge".as_ref(), out.as_os_str()];
    args.extend(good.iter().map(|p| p.as_os_str()));
    ok(&args);
    assert_eq!(read(&out), read(&plain));
}

#[test]
fn part_auto_takes_the_index_from_slurm_or_kubernetes() {
    let dir = tempfile::tempdir().unwrap();
    let path = scene_path("fig5_1");
    let given = render_parts(dir.path(), &path, &["2/3", "3/3"], "png", &[]);
    let out = dir.path().join("auto.png");
    let args = part_args(&path, &out, "auto/3");
    let cases: [(&[(&str, &str)], &PathBuf); 4] = [
        (&[("SLURM_ARRAY_TASK_ID", "2")], &given[0]),
        (&[("SLURM_ARRAY_TASK_ID", "7"), ("SLURM_ARRAY_TASK_MIN", "5")], &given[1]),
        (&[("JOB_COMPLETION_INDEX", "1")], &given[0]),
        // Slurm's variables come first.
        (&[("JOB_COMPLETION_INDEX", "0"), ("SLURM_ARRAY_TASK_ID", "3")], &given[1]),
    ];
    for (env, expected) in cases {
        let (code, err) = host_sim(&args, env);
        assert_eq!(code, 0, "{env:?}: {err}");
        assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(expected).unwrap(), "{env:?}");
        std::fs::remove_file(&out).unwrap();
    }
    let refusals: [(&[(&str, &str)], &str); 5] = [
        (&[], "neither is set"),
        (&[("JOB_COMPLETION_INDEX", "3")], "JOB_COMPLETION_INDEX=3 makes this part 4 of 3, outside 1 to 3"),
        (&[("SLURM_ARRAY_TASK_ID", "0")], "SLURM_ARRAY_TASK_ID=0 makes this part 0 of 3"),
        (&[("SLURM_ARRAY_TASK_ID", "4"), ("SLURM_ARRAY_TASK_MIN", "5")], "makes this part 0 of 3"),
        (&[("SLURM_ARRAY_TASK_ID", "two")], "SLURM_ARRAY_TASK_ID=`two` is not a whole number"),
    ];
    for (env, message) in refusals {
        let (code, err) = host_sim(&args, env);
        assert_eq!(code, 2, "{env:?}: {err}");
        assert!(err.contains(message), "{env:?}: expected `{message}` in: {err}");
        assert!(!out.exists());
    }
}

#[test]
fn part_refuses_what_cannot_be_split() {
    let dir = tempfile::tempdir().unwrap();
    let path = scene_path("fig5_1");
    let ras = dir.path().join("part.ras");
    let png = dir.path().join("part.png");
    let cases: [(&Path, &[&str], &str); 5] = [
        (&ras, &["--part", "1/2"], "a Sun raster has no room for the part's metadata"),
        (&png, &["--part", "1/2", "--palette", "scan"], "--palette scan learns its colour table from the whole image"),
        (&png, &["--part", "1/31"], "31 parts of an image 30 rows high: at most 30"),
        (&png, &["--part", "3/2"], "I counts from 1 to N"),
        (&png, &["--part", "0/2"], "I counts from 1 to N"),
    ];
    for (out, extra, message) in cases {
        let mut args = vec![path.as_os_str(), out.as_os_str(), "--size".as_ref(), "40x30".as_ref()];
        args.extend(extra.iter().map(OsStr::new));
        let (code, err) = host_sim(&args, &[]);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(err.contains(message), "{extra:?}: expected `{message}` in: {err}");
        assert!(files(dir.path()).is_empty(), "{extra:?}: {:?}", files(dir.path()));
    }
    // Without OUT every band would take the scene's IMAGEFILE, each over
    // the last.
    let (code, err) = host_sim(&[path.as_os_str(), "--part".as_ref(), "1/2".as_ref()], &[]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--part writes one band of the image: give each part an OUT of its own"), "{err}");
}

#[test]
fn the_gnu_parallel_recipe_gives_the_single_render() {
    let found = Command::new("parallel").arg("--version").output().is_ok_and(|o| o.status.success());
    if !found {
        // CI installs it (scripts/test-all); elsewhere, say loudly what was not run.
        assert!(std::env::var("CI").as_deref() != Ok("true"), "GNU parallel is missing (apt-get install parallel)");
        eprintln!("SKIPPED: GNU parallel is not installed (apt-get install parallel): the recipe was not run");
        println!("SKIPPED: GNU parallel is not installed (apt-get install parallel): the recipe was not run");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // The recipe runs `host-sim` on the repository's scenes, from a directory of its own.
    std::fs::create_dir_all(dir.path().join("scenes")).unwrap();
    std::fs::copy(scene_path("fig5_3"), dir.path().join("scenes/fig5_3.txt")).unwrap();
    octrace_tests::run_recipe(&octrace_tests::recipe("parallel-local"), dir.path(), HOST_SIM);
    let merged = dir.path().join("fig5_3.png");
    let single = dir.path().join("single.png");
    ok(&[dir.path().join("scenes/fig5_3.txt").as_os_str(), single.as_os_str(), "-q".as_ref()]);
    assert_eq!(std::fs::read(&merged).unwrap(), std::fs::read(&single).unwrap(), "merged parts against one render");
    assert_eq!(files(dir.path()), ["bin", "fig5_3.png", "scenes", "single.png"]);
}
