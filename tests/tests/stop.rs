//! A render can always be stopped, even inside a pixel that takes hours
//! (issue 41): host-sim's Ctrl-C ends it within a fraction of a second and
//! leaves no file. (The board's side: `board.rs`; the studio's workers:
//! `studio.rs`.)

use octrace_tests::board::wedging_scene;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// host-sim's command line as a program (`tests/src/bin/host-sim-cli.rs`).
const HOST_SIM: &str = env!("CARGO_BIN_EXE_host-sim-cli");

#[test]
fn ctrl_c_ends_a_render_of_seconds_a_pixel_at_once_and_leaves_no_file() {
    ctrl_c_ends(&wedging_scene(8), "wedge.png", &[]);
}

#[test]
fn ctrl_c_ends_an_animations_frame_at_once_and_leaves_no_file() {
    let animation = format!("FRAMES 3\n{}", wedging_scene(8));
    // A frame of its tiles (the coherence's), and a frame traced whole.
    ctrl_c_ends(&animation, "wedge.gif", &[]);
    ctrl_c_ends(&animation, "wedge.png", &["--no-coherence"]);
}

/// Renders `scene` to `out` (with `args`) and sends Ctrl-C once its
/// temporary file is there and it is inside its first pixels: it must end
/// at once with exit code 130, saying nothing was written, and leave no
/// file.
fn ctrl_c_ends(scene_text: &str, out: &str, args: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("wedge.txt");
    std::fs::write(&scene, scene_text).unwrap();
    let out = dir.path().join(out);
    let mut child = Command::new(HOST_SIM)
        .arg(&scene)
        .arg(&out)
        .args(["--quiet", "--threads", "2"])
        .args(args)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Rendering: its temporary file is there, and it is inside its first pixels.
    let started = Instant::now();
    let entries = || std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect::<Vec<_>>();
    while entries().len() < 2 {
        assert!(started.elapsed() < Duration::from_secs(30), "no temporary file: {:?}", entries());
        std::thread::sleep(Duration::from_millis(10));
    }
    std::thread::sleep(Duration::from_millis(300));
    assert!(child.try_wait().unwrap().is_none(), "still rendering");
    let sent = Instant::now();
    let kill = Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
    assert!(kill.success());
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        assert!(sent.elapsed() < Duration::from_secs(10), "still running 10 s after Ctrl-C");
        std::thread::sleep(Duration::from_millis(5));
    };
    let elapsed = sent.elapsed();
    let mut stderr = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut stderr).unwrap();
    assert_eq!(status.code(), Some(host_sim::cli::EXIT_STOPPED), "{status:?}: {stderr}");
    assert!(stderr.contains("host-sim: stopped (Ctrl-C); nothing written"), "{stderr}");
    assert!(elapsed < Duration::from_millis(500), "ended {elapsed:?} after Ctrl-C");
    assert_eq!(entries(), ["wedge.txt"], "{}: no image and no temporary file left", out.display());
}
