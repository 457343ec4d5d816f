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

mod recovery;
mod waits;

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
fn an_out_that_cannot_be_written_is_refused_before_the_board_draws() {
    let mut board = board();
    let dir = tempfile::tempdir().unwrap();
    let scene = quick_scene_file(dir.path());
    let out = dir.path().join("no-such-folder").join("seen.png");
    let run = host_sim_board(&[board.port.as_os_str(), scene.as_os_str(), out.as_os_str()]);
    assert_eq!(run.code, 1, "{}", run.stderr);
    let want = format!("cannot write {}: No such file or directory", out.display());
    assert!(run.stderr.contains(&want), "want {want:?} in:\n{}", run.stderr);
    assert!(!run.stderr.contains("drawn by the board"), "the board drew:\n{}", run.stderr);
    assert!(board.alive());
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
