//! "Send to board": the board's picture and verdict, or its errors in the
//! editor; the `/board` endpoint's rules, one send at a time; a hostile board's
//! answers refused.

use super::*;

/// The software board (or `OCTRACE_BOARD_COMMAND`'s) the studio sends to.
fn test_board() -> RunningBoard {
    RunningBoard::for_tests(env!("CARGO_BIN_EXE_software-board"))
}

/// The `#board` figure's state and its verdict's kind and text.
fn board_verdict(browser: &Browser) -> (String, String, String) {
    let v = browser.run(
        "const v = document.getElementById('board-verdict');
         return [document.getElementById('board').dataset.state, v.dataset.verdict, v.textContent];",
    );
    let part = |i: usize| v[i].as_str().unwrap_or_default().to_string();
    (part(0), part(1), part(2))
}

/// Sends the editor's text to the board with `how` (a click or the key)
/// and waits for the answer: the `#board` figure's state.
fn send_to_board(browser: &Browser, how: &dyn Fn(&Browser)) -> (String, String, String) {
    browser.run("document.getElementById('board').dataset.state = 'stale'; return true;");
    how(browser);
    browser.wait_for("['done', 'rejected', 'error'].includes(document.getElementById('board').dataset.state)");
    board_verdict(browser)
}

#[test]
fn send_to_board_shows_the_boards_picture_and_verdict_or_its_errors_in_the_editor() {
    let board = test_board();
    let description = board.describe();
    let (w, h) = (description.panel.width, description.panel.height);
    let patience = PATIENCE.to_string();
    let args = ["--board".as_ref(), board.port.as_os_str(), "--board-patience".as_ref(), patience.as_ref()];
    let studio = Studio::start_with(None, &args);
    let browser = Browser::start((1500, 900));
    browser.goto(&studio.url);
    browser.wait_for("document.body.dataset.ready === 'true'");
    assert_eq!(browser.run("return document.getElementById('send-board').disabled;"), false);

    // A scene of the thesis the board holds: its picture beside the render,
    // identical to host-sim's panel preview, as the page says and as this
    // test sees for itself (the cheapest to trace first: the board may be
    // the emulated Pico).
    let name = ["fig5_4", "fig5_2", "fig5_1"]
        .into_iter()
        .find(|name| fits(&description, &std::fs::read_to_string(scene_path(name)).unwrap()))
        .expect("a scene of the thesis fits the board");
    set_text(&browser, &std::fs::read_to_string(scene_path(name)).unwrap());
    let (state, verdict, said) = send_to_board(&browser, &|b| b.click("#send-board"));
    assert_eq!((state.as_str(), verdict.as_str(), said.as_str()), ("done", "identical", "identical"), "{name}");
    let dir = tempfile::tempdir().expect("a directory");
    let preview = dir.path().join("preview.png");
    host_sim_preview(name, &preview, &format!("{w}x{h}"), "rgb565").unwrap();
    let preview = octrace_images::formats::read(&std::fs::read(&preview).unwrap()).unwrap().to_rgb();
    assert_same("the board's picture", browser.canvas_rgb("board-image"), &preview);
    // Its rows were counted as they came (the page shows them while they do).
    let progress = browser.run(
        "const token = location.pathname.split('/')[1];
         return fetch('/board', { headers: { 'X-Studio-Token': token } }).then((r) => r.json());",
    );
    assert_eq!((&progress["rows"], &progress["height"], &progress["busy"]), (&h.into(), &h.into(), &false.into()));

    // A scene over the board's capacity (which the page's own core holds):
    // the board's error lands in the editor at its line and column, and no
    // picture shows. Sent with the key this time.
    let lights = description.capacities.iter().find(|(name, _)| name == "lights").expect("lights are a capacity").1;
    let light = "LIGHT 1 0 5 5\n";
    let text = light.repeat(lights as usize + 1)
        + "SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nSPHERE 1 1 0 0 0\nVIEWPOINT 0 0 5\n";
    set_text(&browser, &text);
    let (state, verdict, said) = send_to_board(&browser, &|b| press(b, "\u{E009}\u{E008}\u{E007}\u{E008}\u{E009}"));
    assert_eq!((state.as_str(), verdict.as_str()), ("rejected", "errors"), "{said}");
    let errors = browser.run(
        "return [...document.querySelectorAll('#errors li')].map((li) =>
           [li.className, li.dataset.line, li.dataset.column, li.textContent]);",
    );
    let errors = errors.as_array().expect("a list");
    let line = (lights + 1).to_string();
    let want = format!("{line}:1: too many lights: the capacity profile {} holds {lights}", description.profile);
    assert!(
        errors.iter().any(|e| e[0] == "board"
            && e[1] == line.as_str()
            && e[2] == "1"
            && e[3].as_str().is_some_and(|t| t.starts_with(&want))),
        "{want} in {errors:?}"
    );
    let cursor = browser.run("const v = studio.editor.view; return [v.state.selection.main.head, v.hasFocus];");
    assert_eq!(cursor[0], light.len() * lights as usize, "the cursor is at the error");
    assert_eq!(cursor[1], true, "in the editor");
    let picture = browser.run(
        "const c = document.getElementById('board-image');
         return [c.width, c.offsetParent === null];",
    );
    assert_eq!(picture[0], 0, "no picture");
    assert_eq!(picture[1], true, "nothing shown");

    // An error the page finds too is listed once, as the board's.
    set_text(&browser, "VIEWPOINT 0 0 5\nSPHERE 1 x 0 0 0\n");
    let (state, _, _) = send_to_board(&browser, &|b| b.click("#send-board"));
    assert_eq!(state, "rejected");
    let listed = browser.run(
        "return [...document.querySelectorAll('#errors li')].filter((li) => li.textContent.startsWith('2:10:'))
           .map((li) => li.className);",
    );
    assert_eq!(listed, serde_json::json!(["board"]));
}

#[test]
fn the_board_endpoint_keeps_the_security_rules_and_sends_one_at_a_time() {
    // What reaches the board is seen here.
    let board = ScriptedBoard::start(true);
    let studio = Studio::start_with(None, &["--board".as_ref(), board.port.as_os_str()]);
    let port_number = studio.port;
    let token = format!("token={}", studio.token);
    let with_token = |path: &str| format!("{path}?{token}");

    // Without the token, with a wrong one, or from a foreign Host: refused
    // (answered before anything could reach the board).
    assert_eq!(http(port_number, "POST", "/board", &[], b"RDEPTH 2\n").0, 403);
    assert_eq!(http(port_number, "GET", "/board", &[], b"").0, 403);
    assert_eq!(http(port_number, "POST", "/board?token=0123", &[], b"RDEPTH 2\n").0, 403);
    for host in ["evil.example:80", &format!("evil.example:{port_number}"), "127.0.0.1"] {
        let (status, _) = http(port_number, "POST", &with_token("/board"), &[("Host", host)], b"RDEPTH 2\n");
        assert_eq!(status, 421, "Host {host}");
    }
    assert_eq!(http(port_number, "PUT", &with_token("/board"), &[], b"RDEPTH 2\n").0, 405);

    // With the token: the board is named, and a send reaches it.
    let (status, body) = http(port_number, "GET", &with_token("/board"), &[], b"");
    assert_eq!(status, 200);
    let status_json: serde_json::Value = serde_json::from_slice(&body).expect("JSON");
    assert_eq!(status_json["port"], board.port.to_string_lossy().as_ref());
    assert_eq!(status_json["busy"], false);
    let send = {
        let path = with_token("/board");
        std::thread::spawn(move || http(port_number, "POST", &path, &[], b"RDEPTH 2\n"))
    };
    board.wait_for(Kind::Scene);
    // Its hello and its scene, and nothing of the refused requests before.
    assert_eq!(board.received(), [Kind::Hello, Kind::Scene]);
    // One send at a time: a second while the first is under way (the board
    // says it is still working) is refused as busy, and the page sees the
    // board's word.
    let (status, body) = http(port_number, "POST", &with_token("/board"), &[], b"RDEPTH 2\n");
    assert_eq!(status, 409, "{}", String::from_utf8_lossy(&body));
    assert!(String::from_utf8_lossy(&body).starts_with("busy"), "{}", String::from_utf8_lossy(&body));
    let deadline = Instant::now() + HANG_GUARD;
    loop {
        let (_, body) = http(port_number, "GET", &with_token("/board"), &[], b"");
        let status: serde_json::Value = serde_json::from_slice(&body).unwrap();
        assert_eq!(status["busy"], true, "{status}");
        if status["working"].is_number() {
            break;
        }
        assert!(Instant::now() < deadline, "the board's word never reached the page: {status}");
        std::thread::sleep(Duration::from_millis(20));
    }
    // The board falls silent: an error naming it and what it last did, and
    // the board free again.
    board.working.store(false, Ordering::SeqCst);
    let (status, body) = send.join().expect("the first send");
    let said = String::from_utf8_lossy(&body);
    assert_eq!(status, 502, "{said}");
    let want = format!(
        "board at {}: the board fell silent: nothing for 8 s after it said it was still working",
        board.port.display()
    );
    assert!(said.starts_with(&want), "{said}");
    let (_, body) = http(port_number, "GET", &with_token("/board"), &[], b"");
    assert_eq!(serde_json::from_slice::<serde_json::Value>(&body).unwrap()["busy"], false);
    // A board that never answers, with a cap on each send: said at the cap.
    let silent = ScriptedBoard::start(false);
    let args = ["--board".as_ref(), silent.port.as_os_str(), "--board-timeout".as_ref(), "1".as_ref()];
    let studio = Studio::start_with(None, &args);
    let (status, body) = http(studio.port, "POST", &format!("/board?token={}", studio.token), &[], b"RDEPTH 2\n");
    let said = String::from_utf8_lossy(&body);
    assert_eq!(status, 502, "{said}");
    assert!(said.starts_with(&format!("board at {}: no answer within 1 s", silent.port.display())), "{said}");
}

#[test]
fn a_board_that_is_no_serial_port_is_an_error_at_start() {
    let scene = scene_path("fig5_1");
    let out = children::output(Command::new(HOST_SIM).args(["studio", "--board"]).arg(&scene)).expect("runs");
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains(&format!("--board {} is no serial port", scene.display())), "{stderr}");
    // A device, but no serial line: refused at start too, not at the first Send.
    let out = children::output(Command::new(HOST_SIM).args(["studio", "--board", "/dev/null"])).expect("runs");
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("studio: --board /dev/null: cannot open it as a serial port"), "{stderr}");
    assert!(out.stdout.is_empty(), "nothing served: {}", String::from_utf8_lossy(&out.stdout));
}

#[test]
fn send_to_board_refuses_what_a_hostile_board_answers() {
    let software = env!("CARGO_BIN_EXE_software-board");
    let text = std::fs::read(scene_path("fig5_1")).expect("fig5_1");
    // A drawing at a panel it did not describe: an error, not "identical"
    // over no pixel at all.
    let board = RunningBoard::software(software, &["--panel", "160x128", "--misbehave", "draws-at:0x0"]);
    let studio = Studio::start_with(None, &["--board".as_ref(), board.port.as_os_str()]);
    let (status, body) = http(studio.port, "POST", &format!("/board?token={}", studio.token), &[], &text);
    let said = String::from_utf8_lossy(&body);
    assert_eq!(status, 502, "{said}");
    assert!(said.contains("it draws at 0x0 rgb565, but described a 160x128 rgb565 panel"), "{said}");
    // Its errors' terminal escapes reach the page escaped.
    let board = RunningBoard::software(software, &["--panel", "160x128", "--misbehave", "escapes"]);
    let studio = Studio::start_with(None, &["--board".as_ref(), board.port.as_os_str()]);
    let (status, body) = http(studio.port, "POST", &format!("/board?token={}", studio.token), &[], &text);
    let answer: serde_json::Value = serde_json::from_slice(&body).expect("JSON");
    assert_eq!(status, 200, "{answer}");
    let message = answer["errors"][0]["message"].as_str().expect("an error");
    assert!(message.starts_with("\\u{1b}[2J\\u{1b}[31mred"), "{answer}");
    assert!(!message.contains('\u{1b}'), "{answer}");
}
