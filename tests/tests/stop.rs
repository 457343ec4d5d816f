//! A render can always be stopped, even inside a pixel that takes hours
//! (issue 41): host-sim's Ctrl-C ends it inside its first pixels and
//! leaves no file, and so do SIGTERM (`kill`, `timeout`, a job scheduler)
//! and SIGHUP (a closed terminal), as they end a wait for the reader of
//! a FIFO given as the output. (The board's side: `board.rs`; the studio's workers:
//! `studio.rs`.)
//!
//! No wall-clock bound decides these tests: a pixel of their scene takes
//! minutes, so a run that stopped only between pixels would still be
//! running when the generous guards below give up on it.

use octrace_tests::board::wedging_scene;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// host-sim's command line as a program (`tests/src/bin/host-sim-cli.rs`).
const HOST_SIM: &str = env!("CARGO_BIN_EXE_host-sim-cli");

/// How long a guard waits for what takes milliseconds (the temporary
/// file, the exit after Ctrl-C) before it calls the run stuck: far less
/// than a pixel of [`minutes_a_pixel`] takes, far more than a busy machine
/// delays a process.
const GUARD: Duration = Duration::from_secs(60);

/// The board tests' wedging scene (two wide facing mirrors, eight lights,
/// 16² samples a pixel, every sample bouncing as often as it may) and
/// 20,000 spheres out of sight that the naive mode tests every ray
/// against: minutes a pixel on a PC, in every pixel.
fn minutes_a_pixel() -> String {
    let mut text = wedging_scene(8);
    for i in 0..20_000 {
        text += &format!("SPHERE 1 0.1 {} 0 0\n", 2000 + i);
    }
    text
}

#[test]
fn ctrl_c_ends_a_render_of_minutes_a_pixel_inside_it_and_leaves_no_file() {
    ctrl_c_ends(&minutes_a_pixel(), "wedge.png", &[]);
}

#[test]
fn sigterm_and_sighup_end_a_render_inside_a_pixel_and_leave_no_file() {
    // A part's rows stream into its temporary file as they are traced.
    signal_ends(Stop::TERM, &minutes_a_pixel(), "wedge.png", &["--part", "1/1"]);
    signal_ends(Stop::HUP, &format!("FRAMES 3\n{}", minutes_a_pixel()), "wedge.gif", &[]);
}

#[test]
fn a_second_stop_signal_ends_host_sim_at_once_and_leaves_no_file_either() {
    // Two signals delivered together, SIGTERM then SIGHUP: host-sim stopped
    // (SIGSTOP) while both are sent, then let go. The second ends it at
    // once, inside its pixel, whatever the first has done by then.
    signals_end(Stop::TERM, Some(Stop::HUP), &minutes_a_pixel(), "wedge.png", &["--part", "1/1"]);
}

#[test]
fn sigterm_ends_the_wait_for_a_fifos_reader() {
    use std::io::BufRead;
    use std::os::unix::fs::FileTypeExt;
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.txt");
    std::fs::write(&scene, "RASTER 4 3\n").unwrap();
    let fifo = dir.path().join("o.png");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let child = Command::new(HOST_SIM).arg(&scene).arg(&fifo).arg("-q").stderr(Stdio::piped()).spawn().unwrap();
    // Ended if an assertion fails: it would wait on the FIFO for ever.
    struct Ended(std::process::Child);
    impl Drop for Ended {
        fn drop(&mut self) {
            let _ = self.0.kill();
            let _ = self.0.wait();
        }
    }
    let mut child = Ended(child);
    // Waiting, with its handlers installed, once it says so.
    let mut stderr = std::io::BufReader::new(child.0.stderr.take().unwrap());
    let mut said = String::new();
    stderr.read_line(&mut said).unwrap();
    assert!(said.ends_with("o.png is a FIFO: waiting for its reader\n"), "{said}");
    assert!(Command::new("kill").args(["-TERM", &child.0.id().to_string()]).status().unwrap().success());
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut stderr, &mut rest).unwrap();
    let status = child.0.wait().unwrap();
    assert_eq!(status.code(), Some(Stop::TERM.exit_code), "{status:?}: {rest}");
    assert_eq!(rest, "host-sim: stopped (SIGTERM); nothing written\n");
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo(), "still a pipe");
}

#[test]
fn ctrl_c_ends_an_animations_frame_inside_a_pixel_and_leaves_no_file() {
    let animation = format!("FRAMES 3\n{}", minutes_a_pixel());
    // A frame of its tiles (the coherence's), and a frame traced whole.
    ctrl_c_ends(&animation, "wedge.gif", &[]);
    ctrl_c_ends(&animation, "wedge.png", &["--no-coherence"]);
}

/// A signal that stops host-sim: its name for `kill`, host-sim's exit code
/// and its name in host-sim's message.
struct Stop {
    kill: &'static str,
    exit_code: i32,
    said: &'static str,
}

impl Stop {
    const INT: Stop = Stop { kill: "-INT", exit_code: host_sim::cli::EXIT_STOPPED, said: "Ctrl-C" };
    const TERM: Stop = Stop { kill: "-TERM", exit_code: 128 + 15, said: "SIGTERM" };
    const HUP: Stop = Stop { kill: "-HUP", exit_code: 128 + 1, said: "SIGHUP" };
}

fn ctrl_c_ends(scene_text: &str, out: &str, args: &[&str]) {
    signal_ends(Stop::INT, scene_text, out, args);
}

fn signal_ends(signal: Stop, scene_text: &str, out: &str, args: &[&str]) {
    signals_end(signal, None, scene_text, out, args);
}

/// Sends `signal` to process `pid`.
fn send(signal: &str, pid: u32) {
    assert!(Command::new("kill").args([signal, &pid.to_string()]).status().unwrap().success(), "kill {signal}");
}

/// Renders `scene` to `out` (with `args`, in the naive mode) and sends
/// `signal` once its temporary file is there (its handler is installed
/// before) and, most likely, it is inside its first pixels, with `second`
/// delivered together with it if given: it must end with the exit code of
/// one of them before
/// any pixel could end, saying it stopped (nothing written, for one
/// signal), and leave no file.
fn signals_end(signal: Stop, second: Option<Stop>, scene_text: &str, out: &str, args: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("wedge.txt");
    std::fs::write(&scene, scene_text).unwrap();
    let out = dir.path().join(out);
    let mut child = Command::new(HOST_SIM)
        .arg(&scene)
        .arg(&out)
        .args(["--quiet", "--threads", "2", "--accel", "naive"])
        .args(args)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Rendering: its temporary file is there.
    let started = Instant::now();
    let entries = || std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect::<Vec<_>>();
    while entries().len() < 2 {
        assert!(started.elapsed() < GUARD, "no temporary file: {:?}", entries());
        std::thread::sleep(Duration::from_millis(10));
    }
    // Into its first pixels, on any machine but a stalled one (if not,
    // the stop comes before the first ray: the same outcome).
    std::thread::sleep(Duration::from_millis(300));
    assert!(child.try_wait().unwrap().is_none(), "still rendering");
    let sent = Instant::now();
    match &second {
        None => send(signal.kill, child.id()),
        Some(second) => {
            send("-STOP", child.id());
            send(signal.kill, child.id());
            send(second.kill, child.id());
            send("-CONT", child.id());
        }
    }
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        assert!(
            sent.elapsed() < GUARD,
            "still running {GUARD:?} after {}: it did not stop inside a pixel",
            signal.said
        );
        std::thread::sleep(Duration::from_millis(5));
    };
    let mut stderr = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut stderr).unwrap();
    let said = match &second {
        None => {
            assert_eq!(status.code(), Some(signal.exit_code), "{status:?}: {stderr}");
            format!("host-sim: stopped ({}); nothing written", signal.said)
        }
        Some(second) => {
            let (code, said) = match status.code() == Some(signal.exit_code) {
                true => (signal.exit_code, signal.said),
                false => (second.exit_code, second.said),
            };
            assert_eq!(status.code(), Some(code), "{status:?}: {stderr}");
            format!("host-sim: stopped ({said})")
        }
    };
    assert!(stderr.contains(&said), "{stderr}");
    assert_eq!(entries(), ["wedge.txt"], "{}: no image and no temporary file left", out.display());
}
