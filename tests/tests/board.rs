//! `host-sim board` against a running board, as a user meets it: scenes sent
//! in a row to one board, each picture bit-identical to host-sim's; a scene
//! with errors answered at each line and column with nothing drawn; a
//! scene over the board's capacity refused naming it; a transfer cut off
//! half-way, after which the board takes the next scene; garbage, a wrong
//! checksum and a wrong version each answered, the board still alive; and
//! what a drawing that takes hours a pixel, a burst of frames, a host that
//! stops reading, an error flood, a host gone mid-drawing and a scene of the
//! longest size do to it (issue 41): a hello answered within 50 ms by the
//! board's clock, every frame answered, the picture still drawn, the next
//! answer whole; an animation played over the link (issue 39): its first
//! frames each host-sim's `--frame K`, a hello stopping it within 50 ms;
//! and host-sim's waits (issue 46): a drawing of hours a pixel followed
//! while the board says it is working, a board gone silent mid-drawing
//! given up with what it did last, a chatty board ended by its errors'
//! count. Every wait is for an event (`HANG_GUARD` only guards against a
//! hang; host-sim is given the patience to match, `PATIENCE`, except in
//! the tests of its waits, which give a board 800 times slower than a Pico
//! room), and every time checked is the board's own clock's.
//!
//! The board is the software board (`software-board`: the live firmware's
//! logic, `octrace_link::board`, behind a pseudo-terminal), or the command
//! `OCTRACE_BOARD_COMMAND` names (for instance the emulated Pico's `node
//! emulator/run.mjs ELF --serial`), which must print the
//! serial device it serves. The tests ask the board what it is (panel,
//! profile, longest scene) and choose their scenes by it.

use octrace_link::{encode_raw, Kind, Message, Panel, Reason, Refusal, VERSION};
use octrace_tests::board::{dearest_scene, fits, lights, open_pty, wedging_scene, RawHost, RunningBoard, PATIENCE};
use octrace_tests::{host_sim_preview_of, scene_path, HANG_GUARD};
use std::ffi::OsStr;
use std::path::Path;
use std::time::Duration;

/// A board to talk to: `OCTRACE_BOARD_COMMAND`'s command, or the software board.
fn board() -> RunningBoard {
    RunningBoard::for_tests(env!("CARGO_BIN_EXE_software-board"))
}

struct Run {
    code: i32,
    stdout: String,
    stderr: String,
}

/// `host-sim board ARGS...`, in this process, with `--patience PATIENCE`
/// unless ARGS give their own (the tests of host-sim's waits).
fn host_sim_board(args: &[&OsStr]) -> Run {
    let (mut stdout, mut stderr) = (Vec::new(), Vec::new());
    let patience = PATIENCE.to_string();
    let patient: [&OsStr; 2] = ["--patience".as_ref(), patience.as_ref()];
    let own = args.contains(&"--patience".as_ref());
    let args = ["host-sim".as_ref(), "board".as_ref()]
        .into_iter()
        .chain(args.iter().copied())
        .chain(patient.into_iter().filter(|_| !own));
    let code = host_sim::cli::run(args, &mut stdout, &mut stderr);
    // host-sim has closed the port, in this process.
    octrace_tests::children::settle_after_closing();
    let text = |bytes: Vec<u8>| String::from_utf8_lossy(&bytes).into_owned();
    Run { code, stdout: text(stdout), stderr: text(stderr) }
}

/// Sends the scene at `scene` with `--check` and checks the picture written
/// is host-sim's preview of the panel.
fn draws_host_sims_picture(board: &RunningBoard, panel: &str, scene: &Path, dir: &Path) {
    let name = scene.file_stem().expect("a scene file's name").to_string_lossy();
    let out = dir.join(format!("{name}-board.png"));
    let run = host_sim_board(&[board.port.as_os_str(), scene.as_os_str(), out.as_os_str(), "--check".as_ref()]);
    assert_eq!(run.code, 0, "{name}: {}", run.stderr);
    assert!(run.stderr.contains("--check: bit-identical to host-sim's rgb565 render"), "{name}: {}", run.stderr);
    // The board's `done`: its time, and its load's and render's by its clock.
    assert!(run.stderr.contains(" by its clock (load "), "{name}: {}", run.stderr);
    let expected = dir.join(format!("{name}-host.png"));
    host_sim_preview_of(scene, &expected, panel, "rgb565").unwrap();
    let (got, want) = (read_rgb(&out), read_rgb(&expected));
    assert_eq!((got.width, got.height), (want.width, want.height), "{name}");
    assert!(got.data == want.data, "{name}: the board's picture differs from host-sim's");
}

fn read_rgb(path: &Path) -> octrace_images::RgbImage {
    octrace_images::formats::read(&std::fs::read(path).unwrap()).unwrap().to_rgb()
}

/// [`QUICK_SCENE`] written as `quick.txt` in `dir`: what a test draws where
/// any picture serves (the board's recovery, not its tracing, is checked).
fn quick_scene_file(dir: &Path) -> std::path::PathBuf {
    let scene = dir.join("quick.txt");
    std::fs::write(&scene, QUICK_SCENE).unwrap();
    scene
}

#[test]
fn three_scenes_in_a_row_are_each_host_sims_picture() {
    let mut board = board();
    let description = board.describe();
    let panel = format!("{}x{}", description.panel.width, description.panel.height);
    let dir = tempfile::tempdir().unwrap();
    // The cheapest to trace first (the board may be the emulated Pico):
    // a ring of mirror spheres, a helix of fifty, a mirror sphere over
    // the chessboard's rectangles.
    let names: Vec<&str> = ["fig5_4", "fig5_2", "fig5_5", "fig5_1", "fig5_8", "fig5_3", "fig5_7"]
        .into_iter()
        .filter(|name| fits(&description, &std::fs::read_to_string(scene_path(name)).unwrap()))
        .take(3)
        .collect();
    assert_eq!(names.len(), 3, "three of the thesis's scenes fit the board");
    for name in names {
        draws_host_sims_picture(&board, &panel, &scene_path(name), dir.path());
    }
    assert!(board.alive());
}

#[test]
fn a_scene_with_errors_is_answered_at_each_line_and_column_and_nothing_is_drawn() {
    let board = board();
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("bad.txt");
    std::fs::write(&scene, "SPHERE 1 -1 0 0 0\nFOO 3\nRASTER 0 5\nLIGHT 1 2 x 4\n").unwrap();
    let out = dir.path().join("out.png");
    let run = host_sim_board(&[board.port.as_os_str(), scene.as_os_str(), out.as_os_str(), "--check".as_ref()]);
    // Exactly what host-sim prints for the same file.
    let mut stderr = Vec::new();
    let own =
        host_sim::cli::run(["host-sim".as_ref(), scene.as_os_str(), out.as_os_str()], &mut Vec::new(), &mut stderr);
    let own = (own, String::from_utf8_lossy(&stderr).into_owned());
    assert_eq!((run.code, &run.stderr), (own.0, &own.1));
    assert_eq!(run.code, 2);
    let file = scene.display();
    for error in ["1:10: SPHERE radius must be > 0, found -1", "2:1: unknown keyword `FOO`", "4:11: expected a number"]
    {
        assert!(run.stderr.contains(&format!("{file}:{error}")), "{error} in:\n{}", run.stderr);
    }
    assert!(run.stderr.ends_with(&format!("4 error(s) in {file}; nothing rendered\n")), "{}", run.stderr);
    assert!(!out.exists(), "nothing is written");
}

#[test]
fn a_scene_over_the_boards_capacity_is_refused_naming_it() {
    let board = board();
    let description = board.describe();
    let lights = description.capacities.iter().find(|(name, _)| name == "lights").expect("lights are a capacity").1;
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("many-lights.txt");
    let text =
        "LIGHT 1 0 5 5\n".repeat(lights as usize + 1) + "SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nSPHERE 1 1 0 0 0\n";
    std::fs::write(&scene, text).unwrap();
    let run = host_sim_board(&[board.port.as_os_str(), scene.as_os_str()]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    let want = format!(
        "{}:{}:1: too many lights: the capacity profile {} holds {lights} and the scene needs {}; \
         define a profile that holds them with octrace_core::profile! (lights: {}, …)\n",
        scene.display(),
        lights + 1,
        description.profile,
        lights + 1,
        lights + 1
    );
    assert!(run.stderr.starts_with(&want), "want {want:?} in:\n{}", run.stderr);
}

#[test]
fn a_transfer_cut_off_half_way_leaves_the_board_taking_the_next_scene() {
    let mut board = board();
    let panel = board.describe().panel;
    let dir = tempfile::tempdir().unwrap();
    let mut frame = Vec::new();
    Message::Scene { pixels: true, text: QUICK_SCENE.as_bytes() }.encode(1, &mut frame).unwrap();
    // Half a scene, and the host is gone.
    let mut host = RawHost::open(&board.port);
    host.send(&frame[..frame.len() / 2]);
    drop(host);
    let size = format!("{}x{}", panel.width, panel.height);
    let quick = quick_scene_file(dir.path());
    draws_host_sims_picture(&board, &size, &quick, dir.path());
    // A whole scene, and the host is gone after its first row.
    let mut host = RawHost::open(&board.port);
    host.send(&frame);
    let rows = host
        .receive_until(&mut |received| matches!(received, Ok(frame) if matches!(frame.message, Message::Row { .. })));
    assert!(rows, "the board draws");
    drop(host);
    draws_host_sims_picture(&board, &size, &quick, dir.path());
    assert!(board.alive());
}

#[test]
fn a_frame_from_the_host_stops_a_drawing_between_rows() {
    let mut board = board();
    let description = board.describe();
    let text = std::fs::read(scene_path("fig5_1")).unwrap();
    // The scene, and a hello right behind it: there when the first row is drawn.
    let mut frames = Vec::new();
    Message::Scene { pixels: false, text: &text }.encode(0x5ce, &mut frames).unwrap();
    Message::Hello.encode(0x4e11, &mut frames).unwrap();
    let mut host = RawHost::open(&board.port);
    host.send(&frames);
    let mut answers = Vec::new();
    let mut cancelled = None;
    host.receive_until(&mut |received| {
        let frame = received.expect("the board's frames read");
        match frame.message {
            Message::Drawing { .. } | Message::Row { .. } => return false,
            Message::Cancelled { rows } => cancelled = Some(rows),
            _ => {}
        }
        answers.push((frame.tag, frame.message.kind()));
        frame.message.kind() == Kind::Board
    });
    assert_eq!(answers, [(0x5ce, Kind::Cancelled), (0x4e11, Kind::Board)]);
    assert!(cancelled < Some(description.panel.height), "stopped before the last row: {cancelled:?}");
    assert!(board.alive());
}

/// The board's answer to `bytes` from a raw host: the refusal, if that is
/// what comes.
fn answer_to(host: &mut RawHost, bytes: &[u8]) -> Refusal {
    host.send(bytes);
    let mut refusal = None;
    let answered = host.receive_until(&mut |received| {
        refusal = Some(match received {
            Ok(frame) => match frame.message {
                Message::Refused(reason) => Refusal { tag: frame.tag, reason },
                other => panic!("a refusal was due, not {other:?}"),
            },
            Err(refusal) => panic!("the board's answer does not read: {refusal}"),
        });
        true
    });
    assert!(answered, "the board answers {bytes:?}");
    refusal.unwrap()
}

#[test]
fn garbage_a_wrong_checksum_and_a_wrong_version_are_answered_and_the_board_lives_on() {
    let mut board = board();
    let description = board.describe();
    let mut host = RawHost::open(&board.port);
    // A modem's greeting, then a delimiter.
    let refused = answer_to(&mut host, b"AT\r\nATZ\r\n\0");
    assert_eq!(refused.tag, 0, "an unreadable frame's tag is not trusted");
    assert!(matches!(refused.reason, Reason::Undecodable { .. } | Reason::BadChecksum { .. }), "{refused:?}");
    // A hello with a bit flipped on the way.
    let mut hello = Vec::new();
    Message::Hello.encode(0x0102, &mut hello).unwrap();
    hello[3] ^= 0x10;
    assert!(matches!(answer_to(&mut host, &hello), Refusal { tag: 0, reason: Reason::BadChecksum { .. } }));
    // A hello of the next version.
    let mut next = Vec::new();
    encode_raw(VERSION + 1, Kind::Hello.byte(), 77, &[], &mut next).unwrap();
    let wrong = Reason::WrongVersion { expected: VERSION, found: VERSION + 1 };
    assert_eq!(answer_to(&mut host, &next), Refusal { tag: 77, reason: wrong });
    // A board's message, a scene whose flags mean nothing, a scene too long.
    let mut row = Vec::new();
    Message::Row { y: 0, pixels: &[] }.encode(78, &mut row).unwrap();
    let unexpected = Reason::Unexpected { kind: Kind::Row.byte() };
    assert_eq!(answer_to(&mut host, &row), Refusal { tag: 78, reason: unexpected });
    let mut flags = Vec::new();
    encode_raw(VERSION, Kind::Scene.byte(), 79, &[7, b'x'], &mut flags).unwrap();
    let malformed = Reason::Malformed { kind: Kind::Scene.byte() };
    assert_eq!(answer_to(&mut host, &flags), Refusal { tag: 79, reason: malformed });
    let long = vec![b' '; description.max_scene as usize + 1];
    let mut too_long = Vec::new();
    Message::Scene { pixels: false, text: &long }.encode(80, &mut too_long).unwrap();
    let refused = answer_to(&mut host, &too_long);
    assert!(matches!(refused.reason, Reason::TooLong { .. }), "{refused:?}");
    drop(host);
    // Alive, and drawing.
    assert!(board.alive());
    let dir = tempfile::tempdir().unwrap();
    let size = format!("{}x{}", description.panel.width, description.panel.height);
    draws_host_sims_picture(&board, &size, &quick_scene_file(dir.path()), dir.path());
}

#[test]
fn the_board_says_what_it_is() {
    let board = board();
    let run = host_sim_board(&[board.port.as_os_str()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let description = board.describe();
    let Some(first) = run.stdout.lines().next() else { panic!("nothing printed") };
    assert!(first.starts_with(&format!("{}: ", board.port.display())), "{first}");
    let panel = format!("panel: {}x{} rgb565", description.panel.width, description.panel.height);
    assert!(run.stdout.contains(&panel), "{}", run.stdout);
    assert!(run.stdout.contains(&format!("profile {}: objects", description.profile)), "{}", run.stdout);
}

#[test]
fn without_a_port_the_ports_are_listed_and_a_scene_is_not_taken_for_one() {
    let run = host_sim_board(&[]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(!run.stdout.is_empty());
    let scene = scene_path("fig5_1");
    let run = host_sim_board(&[scene.as_os_str()]);
    assert_eq!(run.code, 2);
    assert!(run.stderr.contains("is no serial port: give the board's port first"), "{}", run.stderr);
}

#[test]
fn a_silent_port_is_an_error_naming_it() {
    let (_controller, port) = open_pty().unwrap();
    let scene = scene_path("fig5_1");
    let run = host_sim_board(&[port.as_os_str(), scene.as_os_str(), "--timeout".as_ref(), "1".as_ref()]);
    assert_eq!(run.code, 1);
    let want = format!("host-sim: board at {}: no answer within 1 s", port.display());
    assert!(run.stderr.starts_with(&want), "{}", run.stderr);
}

#[test]
fn a_board_of_another_version_is_refused_clearly() {
    // A board of the next release: it answers every frame in its version.
    let (mut controller, port) = open_pty().unwrap();
    let mut reader = controller.try_clone().unwrap();
    std::thread::spawn(move || {
        use std::io::{Read, Write};
        let mut decoder = octrace_link::Decoder::new(vec![0u8; 1024]);
        let mut chunk = [0u8; 256];
        while let Ok(n) = reader.read(&mut chunk) {
            for &byte in &chunk[..n] {
                if let Some(Ok(frame)) = decoder.push(byte) {
                    let mut answer = Vec::new();
                    encode_raw(VERSION + 1, Kind::Board.byte(), frame.tag, &[0; 20], &mut answer).unwrap();
                    let _ = controller.write_all(&answer);
                }
            }
        }
    });
    let run = host_sim_board(&[port.as_os_str(), "--timeout".as_ref(), "5".as_ref()]);
    assert_eq!(run.code, 1, "{}", run.stderr);
    let want = format!(
        "host-sim: board at {}: the board speaks protocol version {} and this host-sim version {VERSION}",
        port.display(),
        VERSION + 1
    );
    assert!(run.stderr.starts_with(&want), "{}", run.stderr);
}

/// A board that departs from the protocol on command (the software board
/// with `--misbehave HOW`), with a 16 KiB board's profile and a 160×128
/// panel.
fn hostile_board(how: &str, more: &[&str]) -> RunningBoard {
    let mut args = vec!["--profile", "board16k", "--panel", "160x128", "--misbehave", how];
    args.extend(more);
    RunningBoard::software(env!("CARGO_BIN_EXE_software-board"), &args)
}

/// `host-sim board ARGS...` on a thread of its own: its run, or None if it
/// has not ended within `limit` (a run with no end fails the test instead
/// of hanging it).
fn host_sim_board_within(args: &[&OsStr], limit: Duration) -> Option<Run> {
    let args: Vec<std::ffi::OsString> = args.iter().map(|a| a.to_os_string()).collect();
    let (done, ended) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let args: Vec<&OsStr> = args.iter().map(|a| a.as_os_str()).collect();
        let _ = done.send(host_sim_board(&args));
    });
    ended.recv_timeout(limit).ok()
}

#[test]
fn a_drawing_at_another_panel_than_described_or_beyond_the_protocol_is_refused_and_nothing_is_written() {
    let scene = scene_path("fig5_1");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.png");
    for size in ["0x0", "65535x65535", "128x160"] {
        let board = hostile_board(&format!("draws-at:{size}"), &[]);
        let run = host_sim_board(&[board.port.as_os_str(), scene.as_os_str(), out.as_os_str(), "--check".as_ref()]);
        assert_eq!(run.code, 1, "{size}: {}", run.stderr);
        let want = format!("it draws at {size} rgb565, but described a 160x128 rgb565 panel");
        assert!(run.stderr.contains(&want), "{size}: {}", run.stderr);
        assert!(!run.stderr.contains("bit-identical") && !out.exists(), "{size}: {}", run.stderr);
    }
    // A board that describes a panel beyond the protocol's sides.
    let board = RunningBoard::software(env!("CARGO_BIN_EXE_software-board"), &["--panel", "65535x65535"]);
    let run = host_sim_board(&[board.port.as_os_str(), scene.as_os_str(), out.as_os_str(), "--check".as_ref()]);
    assert_eq!(run.code, 1, "{}", run.stderr);
    assert!(
        run.stderr.contains("it describes a 65535x65535 panel; a panel's sides are 1 to 16384 pixels"),
        "{}",
        run.stderr
    );
}

#[test]
fn check_exits_3_when_the_boards_picture_differs_by_a_pixel_in_any_channel() {
    let scene = scene_path("fig5_1");
    // Its first pixel in every channel, or in one alone by its lowest bit.
    for how in ["wrong-pixel", "wrong-pixel:red", "wrong-pixel:green", "wrong-pixel:blue"] {
        let board = hostile_board(how, &[]);
        let run = host_sim_board(&[board.port.as_os_str(), scene.as_os_str(), "--check".as_ref()]);
        assert_eq!(run.code, 3, "{how}: {}", run.stderr);
        let want = "host-sim: board --check: 1 of 20480 pixels differ from host-sim's rgb565 render at 160x128";
        assert!(run.stderr.contains(want), "{how}: {}", run.stderr);
    }
}

#[test]
fn a_board_that_keeps_sending_errors_is_given_up_by_their_count_or_at_the_timeout() {
    let scene = scene_path("fig5_1");
    // Errors move nothing on: more than the scene can have end it.
    let board = hostile_board("errors-every:1", &[]);
    let run = host_sim_board_within(&[board.port.as_os_str(), scene.as_os_str()], HANG_GUARD).expect("it ends");
    assert_eq!(run.code, 1, "{}", run.stderr);
    let want = "it sent more errors than a scene of 999 bytes can have (563)";
    assert!(run.stderr.contains(want), "{}", run.stderr);
    // Slower, capped: at the cap.
    let board = hostile_board("errors-every:20", &[]);
    ends_at_the_cap(&board, &scene, 2);
}

/// host-sim's `--patience` in the tests of its silence allowance: room
/// for a board 800 times slower than a Pico (one that says it is working
/// every 40 ms of its clock is heard every 32 s), while a board held silent
/// is given up within 32 s.
const WAITS_PATIENCE: u32 = 4;

/// The silence allowance of `host-sim board --patience WAITS_PATIENCE`, in
/// seconds.
const WAITS_SILENCE: u64 = host_sim::board::SILENCE.as_secs() * WAITS_PATIENCE as u64;

/// `host-sim board PORT SCENE --timeout SECONDS --patience WAITS_PATIENCE`
/// to `board` ends at the cap.
fn ends_at_the_cap(board: &RunningBoard, scene: &Path, seconds: u64) {
    let (seconds, patience) = (seconds.to_string(), WAITS_PATIENCE.to_string());
    let args = [
        board.port.as_os_str(),
        scene.as_os_str(),
        "--timeout".as_ref(),
        seconds.as_ref(),
        "--patience".as_ref(),
        patience.as_ref(),
    ];
    let run = host_sim_board_within(&args, HANG_GUARD).expect("host-sim board ends");
    assert_eq!(run.code, 1, "{}", run.stderr);
    let want = format!(
        "host-sim: board at {}: the board's answer did not end within {seconds} s (--timeout)",
        board.port.display()
    );
    assert!(run.stderr.starts_with(&want), "{}", run.stderr);
}

/// The wedging scene for `board`, written in `dir`.
fn wedge_file(board: &RunningBoard, dir: &Path) -> std::path::PathBuf {
    let scene = dir.join("wedge.txt");
    std::fs::write(&scene, wedging_scene(lights(&board.describe()))).unwrap();
    scene
}

#[test]
fn a_drawing_whose_pixel_outlasts_the_silence_allowance_is_followed_while_the_board_says_it_is_working() {
    // The wedging scene: hours a pixel, so the board sends no row, only its
    // word that it is still working, for longer than host-sim allows a
    // board to say nothing; host-sim follows it to its cap.
    let board = board();
    let dir = tempfile::tempdir().unwrap();
    ends_at_the_cap(&board, &wedge_file(&board, dir.path()), WAITS_SILENCE + 4);
}

#[test]
fn a_board_gone_silent_mid_drawing_is_given_up_saying_what_it_did_last() {
    let mut board = board();
    let dir = tempfile::tempdir().unwrap();
    let args: Vec<std::ffi::OsString> = vec![
        board.port.clone().into(),
        wedge_file(&board, dir.path()).into(),
        "--patience".into(),
        WAITS_PATIENCE.to_string().into(),
    ];
    let run = std::thread::spawn(move || {
        let args: Vec<&OsStr> = args.iter().map(|a| a.as_os_str()).collect();
        host_sim_board(&args)
    });
    // Drawing for 100 ms of the board's clock (it has said it is working
    // since): then the host takes no more of what it sends. A host-sim that
    // ended before fails the test at once, with what it said.
    board.wait_for("to draw for 100 ms, or host-sim board to end", |times| {
        run.is_finished()
            || !times.idle && times.last_in.zip(times.last_out).is_some_and(|(came, went)| went >= came + 100_000)
    });
    assert_eq!(board.command("hold"), "ok");
    let run = run.join().expect("host-sim board ends");
    assert_eq!(run.code, 1, "{}", run.stderr);
    let silent = format!(
        "host-sim: board at {}: the board fell silent: nothing for {WAITS_SILENCE} s after ",
        board.port.display()
    );
    // What the board did last: its word that it was still working, or the
    // row it sent just before the hold (a busy machine's host can read the
    // first row after the board has drawn for 100 ms: the hold then comes
    // between that row and the board's next word).
    let last = run.stderr.strip_prefix(&silent).unwrap_or_else(|| panic!("{}", run.stderr));
    assert!(last.starts_with("it said it was still working, ") || last.starts_with("row "), "{}", run.stderr);
    assert_eq!(board.command("release"), "ok");
    assert!(board.alive());
}

#[test]
fn a_board_that_reads_slowly_gets_the_whole_scene_while_it_reads() {
    // 28 KB of scene (fig5_1 and a comment) at 10 KiB/s, after what the
    // line holds (about 20 KB): longer than any one write's wait, and each
    // byte the board takes moves the conversation on.
    let board = hostile_board("reads-slowly", &["--max-scene", "65536"]);
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("long.txt");
    let text = std::fs::read_to_string(scene_path("fig5_1")).unwrap();
    std::fs::write(&scene, format!("{text}/* {} */\n", "padding ".repeat(3000))).unwrap();
    let run = host_sim_board(&[board.port.as_os_str(), scene.as_os_str(), "--check".as_ref()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(run.stderr.contains("--check: bit-identical"), "{}", run.stderr);
}

#[test]
fn a_boards_text_is_shown_with_its_control_characters_escaped() {
    let board = hostile_board("escapes", &[]);
    let run = host_sim_board(&[board.port.as_os_str()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(run.stdout.contains(": \\u{1b}]0;pwned\\u{7}\\u{1b}[2Joctrace software board"), "{}", run.stdout);
    let scene = scene_path("fig5_1");
    let run = host_sim_board(&[board.port.as_os_str(), scene.as_os_str()]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains(":1:1: \\u{1b}[2J\\u{1b}[31mred\\u{1b}[0m\\u{a}host-sim: 0 error(s)\n"),
        "{}",
        run.stderr
    );
    assert!(!run.stdout.contains('\u{1b}') && !run.stderr.contains('\u{1b}'));
}

#[test]
fn the_board_reports_every_lines_error_as_host_sim_does() {
    let board = board();
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("five.txt");
    std::fs::write(&scene, "x\nx\nx\nx\nx\n").unwrap();
    let run = host_sim_board(&[board.port.as_os_str(), scene.as_os_str()]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    for line in 1..=5 {
        assert!(run.stderr.contains(&format!("five.txt:{line}:1: unknown keyword `x`")), "line {line}: {}", run.stderr);
    }
    assert!(run.stderr.contains("host-sim: 5 error(s) in "), "{}", run.stderr);
}

/// The longest a board may take, by its own clock, from a hello's last
/// byte to its answer's while it draws: 50 ms (the protocol's promise).
/// Each board's clock is its own (the emulated Pico's cycles, the software
/// board's work and waits), so what this machine gives other programs
/// meanwhile does not count.
const ANSWER_BOUND_US: u64 = 50_000;

/// A scene quick to draw on the emulated Pico (a small sphere; most of the
/// panel background): what the tests draw after what they put the board
/// through.
const QUICK_SCENE: &str = "VIEWPOINT 0 0 10\nLIGHT 10 5 5 5\nSPHERE 1 0.6 0 0 0\n\
                           SURFACE 1 .1 .1 .1 .7 .2 .2 .3 .3 .3 10 0 0\n";

/// [`QUICK_SCENE`] with its sphere going round a square in 8 frames: an animation
/// quick to play on the emulated Pico.
const QUICK_ANIMATION: &str = "FRAMES 8\nVIEWPOINT 0 0 10\nLIGHT 10 5 5 5\n\
                               SPHERE 1 0.6 0 0 0 MOVE 0 0 0 0  2 2 0 0  4 2 2 0  6 0 2 0\n\
                               SURFACE 1 .1 .1 .1 .7 .2 .2 .3 .3 .3 10 0 0\n";

/// Sends `message` with `tag` from `host`.
fn send(host: &mut RawHost, message: Message<'_>, tag: u16) {
    let mut frame = Vec::new();
    message.encode(tag, &mut frame).unwrap();
    host.send(&frame);
}

/// Every frame from the board up to and with `last` (its tag and kind), as
/// (tag, kind), rows left out; a frame that does not read is (0, Refused).
fn answers_until(host: &mut RawHost, last: (u16, Kind)) -> Vec<(u16, Kind)> {
    let mut answers = Vec::new();
    let came = host.receive_until(&mut |received| {
        let answer = received.map_or((0, Kind::Refused), |frame| (frame.tag, frame.message.kind()));
        if answer.1 != Kind::Row {
            answers.push(answer);
        }
        answer == last
    });
    assert!(came, "no {last:?}; came: {answers:?}");
    answers
}

/// Whether the board's `panel` shows host-sim's picture of scene `text` (at
/// the panel's size, in its format).
fn panel_shows(board: &mut RunningBoard, panel: Panel, text: &str) {
    let dir = tempfile::tempdir().unwrap();
    let (scene, expected, picture) =
        (dir.path().join("scene.txt"), dir.path().join("host.png"), dir.path().join("panel.png"));
    std::fs::write(&scene, text).unwrap();
    let size = format!("{}x{}", panel.width, panel.height);
    host_sim_preview_of(&scene, &expected, &size, "rgb565").unwrap();
    assert_eq!(board.command(&format!("panel {}", picture.display())), "ok");
    let (got, want) = (read_rgb(&picture), read_rgb(&expected));
    let differing = got.data.chunks(3).zip(want.data.chunks(3)).filter(|(a, b)| a != b).count();
    assert_eq!(differing, 0, "pixels of the panel that differ from host-sim's picture");
}

/// The board draws scene `text` for `host` (without the rows' pixels) to
/// the end, and its `panel` shows host-sim's picture of it.
fn draws_on_the_panel(board: &mut RunningBoard, panel: Panel, host: &mut RawHost, text: &str, tag: u16) {
    send(host, Message::Scene { pixels: false, text: text.as_bytes() }, tag);
    assert_eq!(answers_until(host, (tag, Kind::Done)), [(tag, Kind::Drawing), (tag, Kind::Done)]);
    panel_shows(board, panel, text);
}

/// Sends the wedging scene (without its rows' pixels) with `tag` and waits
/// for the board to start drawing it.
fn start_wedging_drawing(host: &mut RawHost, description: &host_sim::board::BoardDescription, tag: u16) {
    let text = wedging_scene(lights(description));
    assert!(fits(description, &text), "the wedging scene fits the board");
    send(host, Message::Scene { pixels: false, text: text.as_bytes() }, tag);
    assert_eq!(answers_until(host, (tag, Kind::Drawing)), [(tag, Kind::Drawing)]);
}

/// A hello from `host` while the board draws the wedging scene `drawing`:
/// answered, after `cancelled` at row 0, within [`answer_bound_us`] of its
/// arrival by the board's clock.
fn hello_is_answered_at_once(board: &mut RunningBoard, host: &mut RawHost, drawing: u16) {
    let hello = drawing + 1;
    send(host, Message::Hello, hello);
    let mut cancelled = None;
    let answered = host.receive_until(&mut |received| {
        let frame = received.expect("the board's frames read");
        if let Message::Cancelled { rows } = frame.message {
            cancelled = Some((frame.tag, rows));
        }
        (frame.tag, frame.message.kind()) == (hello, Kind::Board)
    });
    assert!(answered, "the hello is answered");
    assert_eq!(cancelled, Some((drawing, 0)), "the drawing stopped inside its first row");
    let times = board.times();
    let (came, answered) = (times.last_in.unwrap(), times.last_out.unwrap());
    assert!(answered > came, "{times:?}");
    println!("the hello answered {} µs after it came, by the board's clock", answered - came);
    assert!(answered - came <= ANSWER_BOUND_US, "answered {} µs after the hello came", answered - came);
}

#[test]
fn a_hello_during_a_drawing_of_hours_a_pixel_is_answered_within_50_ms_and_the_next_scene_is_drawn_bit_exact() {
    let mut board = board();
    let description = board.describe();
    let mut host = RawHost::open(&board.port);
    start_wedging_drawing(&mut host, &description, 0x3e0);
    // A board with a watchdog feeds it while it draws: it never runs low.
    let first = board.times();
    if let Some(left) = first.watchdog_left {
        let mut last = first;
        while last.now < first.now + 20_000 {
            std::thread::sleep(Duration::from_millis(20));
            last = board.times();
        }
        let fed = last.watchdog_left.expect("the watchdog runs while the board draws");
        assert!(fed + 2_000 >= left, "fed: {left} µs left, then {fed} µs after {} µs", last.now - first.now);
    }
    hello_is_answered_at_once(&mut board, &mut host, 0x3e0);
    draws_on_the_panel(&mut board, description.panel, &mut host, QUICK_SCENE, 0x3e2);
    // Waiting for the host, the board stops its watchdog.
    assert_eq!(board.times().watchdog_left, None);
    assert!(board.alive());
}

#[test]
fn a_burst_of_frames_beyond_the_input_ring_mid_pixel_is_answered_frame_by_frame() {
    let mut board = board();
    let description = board.describe();
    let mut host = RawHost::open(&board.port);
    start_wedging_drawing(&mut host, &description, 1);
    // 150 hellos (1.6 KiB: more than the Pico's 1 KiB input ring) and a
    // scene, in one write.
    let mut burst = Vec::new();
    for tag in 100..250 {
        Message::Hello.encode(tag, &mut burst).unwrap();
    }
    Message::Scene { pixels: false, text: QUICK_SCENE.as_bytes() }.encode(300, &mut burst).unwrap();
    assert!(burst.len() > 1024 + QUICK_SCENE.len());
    host.send(&burst);
    let answers = answers_until(&mut host, (300, Kind::Done));
    let hellos: Vec<(u16, Kind)> = (100..250).map(|tag| (tag, Kind::Board)).collect();
    assert_eq!(answers[0], (1, Kind::Cancelled));
    assert_eq!(answers[1..151], hellos[..]);
    assert_eq!(answers[151..], [(300, Kind::Drawing), (300, Kind::Done)]);
    panel_shows(&mut board, description.panel, QUICK_SCENE);
}

/// Asks `host`'s board for `tag`'s hello once it takes bytes again, and
/// returns how many bytes of earlier answers came before the answer: what
/// the board's USB device itself held (its endpoint and the serial class's
/// buffer, 192 bytes on the Pico), no more.
fn stale_bytes_before_hello(host: &mut RawHost, tag: u16) -> u64 {
    let before = host.bytes_read();
    send(host, Message::Hello, tag);
    let mut answer_len = 0;
    let answered = host.receive_until(&mut |received| match received {
        Ok(frame) if (frame.tag, frame.message.kind()) == (tag, Kind::Board) => {
            let mut again = Vec::new();
            frame.message.encode(frame.tag, &mut again).unwrap();
            answer_len = again.len() as u64;
            true
        }
        _ => false,
    });
    assert!(answered, "the hello is answered");
    let stale = host.bytes_read() - before - answer_len;
    println!("{stale} bytes of the dropped answer came before the next");
    stale
}

#[test]
fn a_host_that_stops_reading_loses_the_rest_of_the_answer_not_the_picture_and_gets_the_next_answer_whole() {
    let mut board = board();
    let panel = board.describe().panel;
    let mut host = RawHost::open(&board.port);
    let since = board.times().now;
    // The host stops reading; its scene, with every row's pixels, comes.
    assert_eq!(board.command("hold"), "ok");
    send(&mut host, Message::Scene { pixels: true, text: QUICK_SCENE.as_bytes() }, 5);
    board.wait_idle_after(since);
    // The panel shows the whole picture all the same.
    panel_shows(&mut board, panel, QUICK_SCENE);
    // Reading again: the next answer, after no more than the USB device held.
    assert_eq!(board.command("release"), "ok");
    let stale = stale_bytes_before_hello(&mut host, 6);
    assert!(stale <= 256, "{stale} bytes of the dropped answer came before the next");
}

#[test]
fn an_error_flood_is_answered_whole_and_one_not_read_leaves_the_next_answer_whole() {
    let mut board = board();
    let description = board.describe();
    // The longest scene the board takes, every line an error.
    let line = "FOO\n";
    let text = line.repeat(description.max_scene as usize / line.len());
    let lines = text.len() / line.len();
    let mut host = RawHost::open(&board.port);
    send(&mut host, Message::Scene { pixels: false, text: text.as_bytes() }, 7);
    let mut errors = 0;
    let mut rejected = None;
    let answered = host.receive_until(&mut |received| {
        match received.expect("the board's frames read").message {
            Message::SceneError(error) => {
                errors += 1;
                assert!(error.message.starts_with("unknown keyword `FOO`"), "{}", error.message);
            }
            Message::Rejected { errors } => rejected = Some(errors),
            other => panic!("{other:?}"),
        }
        rejected.is_some()
    });
    assert!(answered, "the flood ends with rejected");
    assert_eq!(rejected, Some(errors));
    assert!(errors as usize >= lines / 2, "{errors} errors in {lines} lines");
    // A flood (kilobytes of errors: more than the board's ring and its USB
    // device hold) to a host that stops reading.
    let since = board.times().now;
    assert_eq!(board.command("hold"), "ok");
    send(&mut host, Message::Scene { pixels: false, text: line.repeat(400).as_bytes() }, 8);
    board.wait_idle_after(since);
    assert_eq!(board.command("release"), "ok");
    let stale = stale_bytes_before_hello(&mut host, 9);
    assert!(stale <= 256, "{stale} bytes of the dropped answer came before the next");
    assert!(board.alive());
}

#[test]
fn a_host_gone_mid_drawing_leaves_a_board_that_answers_the_next_at_once() {
    let mut board = board();
    let description = board.describe();
    let mut host = RawHost::open(&board.port);
    start_wedging_drawing(&mut host, &description, 0x10);
    // The host's program ends: its USB stack stops reading the port.
    assert_eq!(board.command("hold"), "ok");
    drop(host);
    // The next host.
    let mut host = RawHost::open(&board.port);
    assert_eq!(board.command("release"), "ok");
    hello_is_answered_at_once(&mut board, &mut host, 0x10);
    draws_on_the_panel(&mut board, description.panel, &mut host, QUICK_SCENE, 0x12);
}

#[test]
fn a_hello_during_the_dearest_scene_of_the_longest_size_is_answered_within_50_ms() {
    let mut board = board();
    let description = board.describe();
    // The longest text, every capacity full, every ray meeting every object.
    let text = dearest_scene(&description);
    assert_eq!(text.len(), description.max_scene as usize);
    assert!(fits(&description, &text), "the dearest scene fits the board");
    let mut host = RawHost::open(&board.port);
    send(&mut host, Message::Scene { pixels: false, text: text.as_bytes() }, 0x20);
    assert_eq!(answers_until(&mut host, (0x20, Kind::Drawing)), [(0x20, Kind::Drawing)]);
    // Past the screen lists' set-up (polled too), inside the first pixels.
    let started = board.times().last_out.expect("the drawing message went out");
    while board.times().now < started + 500_000 {
        std::thread::sleep(Duration::from_millis(20));
    }
    hello_is_answered_at_once(&mut board, &mut host, 0x20);
    draws_on_the_panel(&mut board, description.panel, &mut host, QUICK_SCENE, 0x22);
}

#[test]
fn a_kind_only_boards_send_is_unexpected_at_a_board_whatever_its_payload() {
    let board = board();
    let mut host = RawHost::open(&board.port);
    // A board's description and a row, each with a payload that fits
    // neither: the kind is checked first.
    for kind in [Kind::Board, Kind::Row, Kind::Refused] {
        let mut frame = Vec::new();
        encode_raw(VERSION, kind.byte(), 0x77, &[0xff], &mut frame).unwrap();
        assert_eq!(
            answer_to(&mut host, &frame),
            Refusal { tag: 0x77, reason: Reason::Unexpected { kind: kind.byte() } }
        );
    }
}

#[test]
fn an_animations_first_frames_are_each_host_sims_frame_and_a_still_is_drawn_after_it() {
    let mut board = board();
    let description = board.describe();
    let panel = format!("{}x{}", description.panel.width, description.panel.height);
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("quick-animation.txt");
    std::fs::write(&scene, QUICK_ANIMATION).unwrap();
    let out = dir.path().join("last.png");
    let run = host_sim_board(&[board.port.as_os_str(), scene.as_os_str(), out.as_os_str(), "--check".as_ref()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(
        run.stderr.contains("--check: 3 frames, each bit-identical to host-sim's --frame K rgb565 render"),
        "{}",
        run.stderr
    );
    for frame in 0..3 {
        assert!(run.stderr.contains(&format!("frame {frame} drawn by the board")), "{}", run.stderr);
    }
    // Every pixel traced in the first frame, fewer after it on a board
    // whose profile follows the motion (the same pictures otherwise).
    let traced: Vec<u64> = run
        .stderr
        .lines()
        .filter_map(|line| line.split(", ").nth(1)?.strip_suffix(" pixels traced")?.parse().ok())
        .collect();
    assert_eq!(traced.len(), 3, "{}", run.stderr);
    assert_eq!(traced[0], u64::from(description.panel.width) * u64::from(description.panel.height));
    // OUT is the last frame followed: host-sim's frame 2.
    let expected = dir.path().join("frame2.png");
    let preview = host_sim::cli::run(
        [
            "host-sim".as_ref(),
            scene.as_os_str(),
            expected.as_os_str(),
            "--frame".as_ref(),
            "2".as_ref(),
            "--size".as_ref(),
            panel.as_ref(),
            "--color".as_ref(),
            "rgb565".as_ref(),
        ],
        &mut Vec::new(),
        &mut Vec::new(),
    );
    assert_eq!(preview, 0);
    assert!(read_rgb(&out).data == read_rgb(&expected).data, "OUT is the board's frame 2");
    // Stopped by the hello: the board takes a still as before.
    let mut host = RawHost::open(&board.port);
    draws_on_the_panel(&mut board, description.panel, &mut host, QUICK_SCENE, 0x590);
}

#[test]
fn a_hello_stops_a_playing_animation_within_50_ms() {
    let mut board = board();
    let panel = board.describe().panel;
    let mut host = RawHost::open(&board.port);
    send(&mut host, Message::Scene { pixels: false, text: QUICK_ANIMATION.as_bytes() }, 0x5a0);
    // Until its first frame is drawn: then it plays on.
    let mut kinds = Vec::new();
    let played = host.receive_until(&mut |received| {
        let frame = received.expect("the board's frames read");
        if let Message::Drawing { frames, .. } = frame.message {
            assert_eq!(frames, 8);
        }
        if frame.message.kind() != Kind::Run {
            kinds.push((frame.tag, frame.message.kind()));
        }
        matches!(frame.message, Message::FrameDrawn { frame: 0, .. })
    });
    assert!(played, "the first frame is drawn: {kinds:?}");
    assert_eq!(kinds, [(0x5a0, Kind::Drawing), (0x5a0, Kind::FrameDrawn)]);
    send(&mut host, Message::Hello, 0x5a1);
    let mut stopped = None;
    let answered = host.receive_until(&mut |received| {
        let frame = received.expect("the board's frames read");
        if let Message::Stopped { frames } = frame.message {
            stopped = Some((frame.tag, frames));
        }
        (frame.tag, frame.message.kind()) == (0x5a1, Kind::Board)
    });
    assert!(answered, "the hello is answered");
    let (tag, frames) = stopped.expect("the animation's answer ends with stopped");
    assert!(tag == 0x5a0 && frames >= 1, "stopped after {frames} frames");
    let times = board.times();
    let (came, answered) = (times.last_in.unwrap(), times.last_out.unwrap());
    assert!(answered > came, "{times:?}");
    println!("the hello answered {} µs after it came, by the board's clock", answered - came);
    assert!(answered - came <= ANSWER_BOUND_US, "answered {} µs after the hello came", answered - came);
    draws_on_the_panel(&mut board, panel, &mut host, QUICK_SCENE, 0x5a2);
    assert!(board.alive());
}
