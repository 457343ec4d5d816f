//! host-sim's waits on a board that misbehaves (issue 46): a drawing at another
//! panel, a wrong pixel, a flood of errors, a pixel of hours followed while the
//! board says it is working, a board gone silent given up with what it did
//! last, a board that reads slowly, a board's text escaped.

use super::*;

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
