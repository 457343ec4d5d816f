//! The scene studio (`host-sim studio`) in a real browser: Debian's
//! chromium, headless, driven over WebDriver by chromedriver. The page runs
//! octrace-core compiled to WebAssembly; these tests check that what it
//! shows is host-sim's image bit for bit, that a user can place, render and
//! save with the mouse, that "Send to board" shows a board's errors and
//! picture, that a render or draft of hours a pixel is stopped by the next
//! at once, and that the server keeps its security rules.
//!
//! The board is the software board, or the command `OCTRACE_BOARD_COMMAND` names
//! (as in tests/tests/board/: [`RunningBoard::for_tests`]).
//!
//! `OCTRACE_SCREENSHOTS=1` also writes the README's screenshots to
//! `docs/studio/`.

use host_sim::{load_bytes, new_scene, render, RenderOptions, RgbImage};
use octrace_core::panel::Dithering;
use octrace_core::AccelMode;
use octrace_images::palette::{self, PaletteMode};
use octrace_link::{BoardInfo, Capacities, Decoder, Kind, Message, Panel, PixelFormat};
use octrace_tests::board::{fits, open_pty, wedging_scene, RunningBoard, PATIENCE};
use octrace_tests::children;
use octrace_tests::webdriver::{http, http_with_head, Browser};
use octrace_tests::{host_sim_preview, repo, scene_path, scenes, HANG_GUARD};
use std::ffi::OsStr;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

mod board;
mod editor;
mod security;
mod time;

/// The host-sim binary, built for this test run: the tests' copy of its
/// command line (`host_sim::cli::run`, as `host-sim` is), which cargo
/// builds with the tests (a `cargo build -p host-sim` here would build the
/// libraries a second time, with host-sim's features alone).
const HOST_SIM: &str = env!("CARGO_BIN_EXE_host-sim-cli");

/// A running `host-sim studio`, stopped (Ctrl-C) on drop, and what it
/// has written on its standard error so far.
struct Studio {
    child: Child,
    url: String,
    port: u16,
    token: String,
    log: std::sync::Arc<std::sync::Mutex<String>>,
    logging: Option<std::thread::JoinHandle<()>>,
}

impl Studio {
    fn start(scene: Option<&Path>) -> Studio {
        Studio::start_with(scene, &[])
    }

    /// `host-sim studio [SCENE] ARGS...`, run in SCENE's directory (so the
    /// page names it as a user would, not by a scratch directory's path).
    fn start_with(scene: Option<&Path>, args: &[&OsStr]) -> Studio {
        Studio::start_in(scene, args, &[])
    }

    /// [`Studio::start_with`] with the environment variables `env` set.
    fn start_in(scene: Option<&Path>, args: &[&OsStr], env: &[(&str, &OsStr)]) -> Studio {
        let mut command = Command::new(HOST_SIM);
        command.envs(env.iter().copied());
        if let Some(directory) = scene.and_then(Path::parent).filter(|d| !d.as_os_str().is_empty()) {
            command.current_dir(directory);
        }
        let scene = scene.map(|path| path.file_name().expect("a file"));
        command.arg("studio").args(scene).args(args).stdout(Stdio::piped()).stderr(Stdio::piped());
        let mut child = children::spawn(&mut command).expect("host-sim studio starts");
        let mut first = String::new();
        BufReader::new(child.stdout.take().expect("stdout")).read_line(&mut first).expect("a first line");
        let url = first.trim().to_string();
        let rest =
            url.strip_prefix("http://127.0.0.1:").unwrap_or_else(|| panic!("the first line is the address: {url}"));
        let (port, token) = rest.split_once("/?token=").expect("port and token");
        let (port, token) = (port.parse().expect("a port"), token.to_string());
        assert!(token.len() >= 32, "a long token: {token}");
        // Its standard error, read as it comes (a pipe left unread would
        // stop a studio that says much).
        let log = std::sync::Arc::new(std::sync::Mutex::new(String::new()));
        let stderr = child.stderr.take().expect("stderr");
        let written = std::sync::Arc::clone(&log);
        let logging = std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                let mut log = written.lock().expect("the log");
                log.push_str(&line);
                log.push('\n');
            }
        });
        Studio { child, url, port, token, log, logging: Some(logging) }
    }

    /// Waits until what the studio has written on its standard error
    /// satisfies `done`.
    fn wait_for_log(&self, what: &str, done: impl Fn(&str) -> bool) {
        let deadline = Instant::now() + HANG_GUARD;
        while !done(&self.log.lock().expect("the log")) {
            assert!(Instant::now() < deadline, "the studio never logged {what}");
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// Sends SIGINT (what Ctrl-C sends) and waits for the exit; its status
    /// and all it wrote on its standard error.
    fn interrupt(&mut self) -> (std::process::ExitStatus, String) {
        let status = children::output(Command::new("kill").args(["-INT", &self.child.id().to_string()]))
            .expect("kill runs")
            .status;
        assert!(status.success());
        let deadline = Instant::now() + HANG_GUARD;
        loop {
            if let Some(status) = self.child.try_wait().expect("wait") {
                if let Some(logging) = self.logging.take() {
                    logging.join().expect("the log's reader");
                }
                return (status, self.log.lock().expect("the log").clone());
            }
            assert!(Instant::now() < deadline, "the studio did not stop on SIGINT");
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for Studio {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// host-sim's render of scene `text` (at its RASTER, or `size`).
fn host_render(text: &str, size: Option<(u32, u32)>) -> host_sim::Rendered {
    let mut scene = new_scene();
    load_bytes("scene", text.as_bytes(), &mut scene).unwrap_or_else(|e| panic!("the scene parses: {e}"));
    render(&mut scene, &RenderOptions { size, ..Default::default() }).expect("renders")
}

fn assert_same(name: &str, canvas: (u32, u32, Vec<u8>), expected: &RgbImage) {
    let (w, h, pixels) = canvas;
    assert_eq!((w, h), (expected.width, expected.height), "{name}: size");
    let differing = pixels.chunks(3).zip(expected.data.chunks(3)).filter(|(a, b)| a != b).count();
    assert_eq!(differing, 0, "{name}: {differing} pixels differ from host-sim's");
}

/// `text` with its RASTER line replaced (or one added).
fn with_raster(text: &str, w: u32, h: u32) -> String {
    let kept: Vec<&str> = text.lines().filter(|l| !l.trim_start().to_ascii_uppercase().starts_with("RASTER")).collect();
    format!("RASTER {w} {h}\n{}\n", kept.join("\n"))
}

fn screenshot(browser: &Browser, name: &str) {
    if std::env::var_os("OCTRACE_SCREENSHOTS").is_some_and(|v| v != "0") {
        let dir = repo().join("docs/studio");
        std::fs::create_dir_all(&dir).expect("docs/studio");
        std::fs::write(dir.join(format!("{name}.png")), browser.screenshot()).expect("screenshot written");
    }
}

/// Sets the editor's text as if typed (undoable, drafts follow).
fn set_text(browser: &Browser, text: &str) {
    let quoted = serde_json::to_string(text).expect("json");
    browser.run(&format!("studio.setText({quoted}); return true;"));
}

fn render_and_wait(browser: &Browser) {
    browser.run("document.getElementById('image').dataset.state = 'stale'; return true;");
    browser.click("#render");
    browser.wait_for("document.getElementById('image').dataset.state === 'done'");
}

const START: &str = "/* placed with the studio */\nVIEWPOINT 0 4 12\nORIGIN 0 0 0\nRASTER 96 72\n\
                     BACKGROUND 0.1 0.1 0.15\nLIGHT 12 -5 8 6\n";

#[test]
fn a_user_places_a_sphere_renders_and_saves_and_every_view_is_host_sims() {
    let dir = tempfile::tempdir().expect("a directory");
    let scene_path = dir.path().join("placed.txt");
    std::fs::write(&scene_path, START).expect("scene written");
    let studio = Studio::start(Some(&scene_path));
    let browser = Browser::start((1500, 900));
    browser.goto(&studio.url);
    browser.wait_for("document.body.dataset.ready === 'true'");

    // Place a sphere the thesis's way: press on the x–z plane and drag up
    // for its height, then drag for its radius.
    browser.click("#toolbar button[data-tool=sphere]");
    browser.drag("#wire", (0, 40), (0, 10));
    browser.drag("#wire", (0, 0), (40, 0));
    let text = scene_text(&browser);
    assert!(
        text.contains("SPHERE 1 "),
        "a sphere was placed:\n{text}\n{}",
        browser.run("return JSON.stringify({tool: studio.tool, placing: studio.placing, log: studio.log});")
    );
    // Its surface: red into diffuse, from the 16 colours, and a reflection.
    browser.run("document.getElementById('surface-target').value = '4'; return true;");
    browser.click(".swatches button[data-colour='2']");
    browser.run(
        "const s = document.querySelector('#panel input[data-field=reflection]');
         s.value = '0.25'; s.dispatchEvent(new Event('change')); return true;",
    );
    browser.wait_for("/SURFACE 1 0\\.1 0\\.1 0\\.1 1 0 0 .* 0\\.25 0/.test(studio.editor.text())");
    render_and_wait(&browser);
    screenshot(&browser, "placed");
    browser.click("#save-scene");
    browser.wait_for("document.body.dataset.saved");
    let saved = std::fs::read_to_string(&scene_path).expect("the scene was saved");
    assert!(saved.contains("SPHERE 1 ") && saved.starts_with(START), "saved:\n{saved}");
    let expected = host_render(&saved, None);
    assert_same("placed sphere", browser.canvas_rgb("image"), &expected.image);

    // Each display mode: the 256-colour modes are host-sim --palette, the
    // panels host-sim's --color previews at the panel size (embedded-graphics'
    // conversion for rgb565; the panels of few levels dithered by the
    // chosen method, bayer for the last).
    for (code, mode) in
        [(1, PaletteMode::Scan), (2, PaletteMode::Dither), (3, PaletteMode::Coarse), (4, PaletteMode::Gray)]
    {
        browser.run(&format!(
            "const d = document.getElementById('display'); d.value = '{code}';
             d.dispatchEvent(new Event('change')); return true;"
        ));
        browser.wait_for(&format!("document.getElementById('image').dataset.display === '{code}'"));
        let shown = palette::apply(&expected.image, &expected.objects, mode).to_rgb();
        assert_same(mode.name(), browser.canvas_rgb("image"), &shown);
    }
    for (code, name, dither) in
        [(5, "rgb565", None), (6, "gray4", None), (7, "mono", None), (9, "bwr", None), (7, "mono", Some("bayer"))]
    {
        // The method's code is its place in the core's list.
        let method = dither.map_or(Dithering::default(), |d| Dithering::from_name(d).unwrap());
        let method_code = Dithering::ALL.iter().position(|&d| d == method).unwrap();
        browser.run(&format!(
            "document.getElementById('panel-size').value = '40x30';
             document.getElementById('dither').value = '{method_code}';
             const d = document.getElementById('display'); d.value = '{code}';
             d.dispatchEvent(new Event('change')); return true;"
        ));
        browser.wait_for(&format!(
            "document.getElementById('image').dataset.display === '{code}'
                 && document.getElementById('image').dataset.dither === '{method_code}'
                 && document.getElementById('image').dataset.state === 'done'"
        ));
        // host-sim --size 40x30 --color NAME [--dither METHOD], as a Targa
        // (RGB, or a colour table).
        let out = dir.path().join(format!("{name}.tga"));
        let args = ["host-sim", scene_path.to_str().unwrap(), out.to_str().unwrap(), "--size", "40x30"];
        let dither = dither.map(|d| ["--dither", d]).into_iter().flatten();
        let (mut stdout, mut stderr) = (Vec::new(), Vec::new());
        let args = args.into_iter().chain(["--color", name, "--quiet"]).chain(dither);
        let code = host_sim::cli::run(args, &mut stdout, &mut stderr);
        assert_eq!(code, 0, "{}", String::from_utf8_lossy(&stderr));
        let panel = octrace_images::formats::read(&std::fs::read(&out).unwrap()).expect("host-sim's preview").to_rgb();
        assert_same(name, browser.canvas_rgb("image"), &panel);
    }
    browser.run("const d = document.getElementById('display'); d.value = '0'; d.dispatchEvent(new Event('change')); return true;");
    browser.wait_for("document.getElementById('image').dataset.state === 'done' && document.getElementById('image').dataset.display === '0'");

    // Image files: what the page writes is host-sim's file format, and
    // reading it back shows the same pixels.
    for (format, name) in [(0, "PNG"), (1, "Targa"), (2, "Sun raster")] {
        let encoded = browser.run(&format!("return btoa(String.fromCharCode(...studio.imageBytes(0, {format})));"));
        let bytes = octrace_tests::webdriver::base64_decode(encoded.as_str().expect("bytes"));
        let read = octrace_images::formats::read(&bytes).unwrap_or_else(|e| panic!("the page's {name} reads: {e}"));
        assert_eq!(read.to_rgb(), expected.image, "{name}");
    }
    // In a 256-colour mode the file is indexed, as host-sim --palette writes.
    let encoded = browser.run("return btoa(String.fromCharCode(...studio.imageBytes(2, 0)));");
    let bytes = octrace_tests::webdriver::base64_decode(encoded.as_str().expect("bytes"));
    let dithered = palette::apply(&expected.image, &expected.objects, PaletteMode::Dither);
    assert_eq!(octrace_images::formats::read(&bytes).expect("indexed PNG"), dithered);

    // Undo takes the last edit back; redo restores it.
    let before = scene_text(&browser);
    browser.run("studio.undo(); return true;");
    assert_ne!(scene_text(&browser), before);
    browser.run("studio.redo(); return true;");
    assert_eq!(scene_text(&browser), before);

    // A file changed on disk since it was loaded is not overwritten without
    // asking: declining keeps the other program's text.
    std::fs::write(&scene_path, "/* changed elsewhere */\n").expect("written");
    set_text(&browser, &format!("{saved}/* more */\n"));
    browser.click("#save-scene");
    let deadline = Instant::now() + HANG_GUARD;
    let question = loop {
        if let Some(q) = browser.alert_text() {
            break q;
        }
        assert!(Instant::now() < deadline, "no question about the changed file");
        std::thread::sleep(Duration::from_millis(25));
    };
    assert!(question.contains("changed on disk"), "{question}");
    browser.answer_alert(false);
    assert_eq!(std::fs::read_to_string(&scene_path).unwrap(), "/* changed elsewhere */\n");

    // Unsaved work survives a reload.
    browser.goto(&studio.url);
    browser.wait_for("document.body.dataset.ready === 'true'");
    assert_eq!(scene_text(&browser), format!("{saved}/* more */\n"));

    // Errors at line and column as you type.
    set_text(&browser, "VIEWPOINT 0 0 5\nSPHERE 1 x 0 0 0\n");
    browser.wait_for("document.querySelector('#errors li')");
    let error: String =
        browser.run("return document.querySelector('#errors li').textContent;").as_str().unwrap().into();
    assert!(error.starts_with("2:10:"), "{error}");
    // Every line's error, as host-sim and the board report them.
    set_text(&browser, "x\nx\nx\nx\nx\n");
    let lines = browser.run("return [...document.querySelectorAll('#errors li')].map((li) => li.dataset.line);");
    assert_eq!(lines, serde_json::json!(["1", "2", "3", "4", "5"]));
}

#[test]
fn the_canvas_is_host_sims_image_for_every_scene() {
    let studio = Studio::start(None);
    let browser = Browser::start((1500, 900));
    browser.goto(&studio.url);
    browser.wait_for("document.body.dataset.ready === 'true'");
    // Started without --board: no board to send to, and the button says so.
    let send = browser.run("const b = document.getElementById('send-board'); return [b.disabled, b.title];");
    assert_eq!(send[0], true);
    assert!(send[1].as_str().is_some_and(|t| t.contains("--board PORT")), "{send}");
    // The Process menu starts at host-sim's --accel default (the core's),
    // its code the mode's place in the core's list.
    let default = AccelMode::ALL.iter().position(|&m| m == AccelMode::default()).expect("a listed mode");
    let process = browser.run("return document.getElementById('accel').value;");
    assert_eq!(process, serde_json::json!(default.to_string()), "the Process menu's first choice");
    // fig5_1 at its own RASTER, the rest small; every process mode.
    let modes = ["naive", "octree", "dda"];
    for (i, (name, path)) in scenes().into_iter().enumerate() {
        let original = std::fs::read_to_string(&path).expect("scene");
        let text = if name == "fig5_1" { original } else { with_raster(&original, 64, 48) };
        let (accel, parallel, partition) = match i % 4 {
            0 => ("3", true, "tiles"),
            1 => ("2", true, "equal4"),
            2 => ("1", false, "tiles"),
            _ => ("0", true, "tiles"),
        };
        browser.run(&format!(
            "document.getElementById('accel').value = '{accel}';
             document.getElementById('parallel').checked = {parallel};
             document.getElementById('partition').value = '{partition}'; return true;"
        ));
        set_text(&browser, &text);
        render_and_wait(&browser);
        let expected = host_render(&text, None);
        assert_same(
            &format!(
                "{name} ({} {partition})",
                modes.get(accel.parse::<usize>().unwrap_or(0).saturating_sub(1)).unwrap_or(&"auto")
            ),
            browser.canvas_rgb("image"),
            &expected.image,
        );
    }

    // The draft while typing on fig5_3 at 160×120: from the last keystroke
    // to the finished draft, measured in the page (reported, not asserted:
    // speed targets live in benchmarks).
    let fig5_3 = std::fs::read_to_string(scene_path("fig5_3")).expect("fig5_3");
    set_text(&browser, &fig5_3);
    browser.wait_for("document.getElementById('draft').dataset.state === 'done'");
    let mut latencies = Vec::new();
    for _ in 0..11 {
        browser.type_into_element(&browser.run("return studio.editor.view.contentDOM;"), " ");
        browser.wait_for("document.getElementById('draft').dataset.state === 'done'");
        latencies.push(browser.run("return studio.draftLatency;").as_f64().expect("a latency"));
    }
    latencies.sort_by(f64::total_cmp);
    println!(
        "draft latency, fig5_3 at 160x120, after the last keystroke: median {:.0} ms (all: {latencies:.0?})",
        latencies[latencies.len() / 2]
    );
    assert!(latencies.iter().all(|&l| l > 0.0), "latencies are measured");
}

#[test]
fn a_render_or_draft_of_hours_a_pixel_is_stopped_by_the_next_at_once() {
    let studio = Studio::start(None);
    let browser = Browser::start((1200, 800));
    browser.goto(&studio.url);
    browser.wait_for("document.body.dataset.ready === 'true'");
    let wedge = with_raster(&wedging_scene(8), 16, 12);
    let next = with_raster(&std::fs::read_to_string(scene_path("fig5_1")).expect("fig5_1"), 64, 48);
    for parallel in [false, true] {
        browser.run(&format!("document.getElementById('parallel').checked = {parallel}; return true;"));
        // Its draft and its render start, and would take hours.
        set_text(&browser, &wedge);
        std::thread::sleep(Duration::from_millis(300));
        browser.run("document.getElementById('image').dataset.state = 'stale'; return true;");
        browser.click("#render");
        browser.wait_for("document.getElementById('image').dataset.state === 'rendering'");
        std::thread::sleep(Duration::from_millis(300));
        // The next scene's draft and render come as if nothing ran before
        // (waited for, as long as a busy machine takes: were the wedge not
        // stopped, they would not come within hours).
        set_text(&browser, &next);
        browser.wait_for(
            "document.getElementById('draft').dataset.state === 'done' && \
             document.getElementById('draft').dataset.seq === String(studio.draftSeq)",
        );
        render_and_wait(&browser);
        assert_same(
            &format!("fig5_1 after the wedge (parallel: {parallel})"),
            browser.canvas_rgb("image"),
            &host_render(&next, None).image,
        );
    }
    // An animation's players too: a frame of hours a pixel, its draft and
    // render under way, is stopped by the next text, whose frames come
    // (the draft's player is the draft's worker pair).
    let dir = tempfile::tempdir().expect("a directory");
    let animation = dir.path().join("animation.txt");
    let animated = with_raster(&std::fs::read_to_string(scene_path("anim_fig5_1")).expect("anim_fig5_1"), 64, 48);
    std::fs::write(&animation, &animated).expect("the animation");
    set_text(&browser, &format!("FRAMES 2\n{wedge}"));
    browser.run(
        "const s = document.getElementById('frame'); s.value = '1'; s.dispatchEvent(new Event('input')); return true;",
    );
    std::thread::sleep(Duration::from_millis(300));
    set_text(&browser, &animated);
    slide_to(&browser, 1);
    assert_same("frame 1 after the wedge's", browser.canvas_rgb("image"), &host_frame(&animation, 1, None));
}

/// Presses `key` (a WebDriver key string) on the page, the focus in none
/// of its fields (nor in the editor).
fn press(browser: &Browser, key: &str) {
    browser.run(
        "let focused = document.activeElement;
         while (focused && focused.shadowRoot && focused.shadowRoot.activeElement) focused = focused.shadowRoot.activeElement;
         if (focused) focused.blur(); return true;",
    );
    browser.keys(key);
}

fn scene_text(browser: &Browser) -> String {
    browser.run("return studio.editor.text();").as_str().expect("text").to_string()
}

/// The texts of the editor's elements `css` selects.
fn editor_texts(browser: &Browser, css: &str) -> Vec<String> {
    let texts = in_editor(browser, &format!("return [...root.querySelectorAll('{css}')].map((e) => e.textContent);"));
    serde_json::from_value(texts).expect("texts")
}

/// Whatever the page's Content-Security-Policy refused, and its script
/// errors (the page keeps them in `studio.log`).
fn page_log(browser: &Browser) -> serde_json::Value {
    browser.run("return studio.log || [];")
}

/// A board the test plays at the end of a pseudo-terminal: it records the
/// kind of every frame that reaches it; it answers a hello (with a 2×2
/// panel's description) if `answering`; it answers a scene with
/// `drawing`, then says it is still working, every 50 ms, while `working`.
/// Otherwise it says nothing.
struct ScriptedBoard {
    port: PathBuf,
    received: Arc<Mutex<Vec<Kind>>>,
    working: Arc<AtomicBool>,
}

impl ScriptedBoard {
    fn start(answering: bool) -> ScriptedBoard {
        let (controller, port) = open_pty().expect("a pseudo-terminal");
        let received = Arc::new(Mutex::new(Vec::new()));
        let working = Arc::new(AtomicBool::new(true));
        // The scene's tag, once one came.
        let scene = Arc::new(Mutex::new(None));
        let mut writer = controller.try_clone().expect("a second handle");
        let (keeps, drawing) = (Arc::clone(&working), Arc::clone(&scene));
        std::thread::spawn(move || loop {
            let tag = *drawing.lock().expect("the scene's tag");
            if let Some(tag) = tag.filter(|_| keeps.load(Ordering::SeqCst)) {
                let mut frame = Vec::new();
                Message::Working { elapsed: None }.encode(tag, &mut frame).expect("encoded");
                let _ = std::io::Write::write_all(&mut writer, &frame);
            }
            std::thread::sleep(Duration::from_millis(50));
        });
        let seen = Arc::clone(&received);
        std::thread::spawn(move || {
            let mut controller = controller;
            let mut decoder = Decoder::for_board(vec![0u8; 1 << 16]);
            let mut chunk = [0u8; 4096];
            loop {
                let n = match std::io::Read::read(&mut controller, &mut chunk) {
                    Ok(n) if n > 0 => n,
                    // No host has it open (yet, or any more).
                    _ => {
                        std::thread::sleep(Duration::from_millis(10));
                        continue;
                    }
                };
                for &byte in &chunk[..n] {
                    let Some(Ok(frame)) = decoder.push(byte) else { continue };
                    seen.lock().expect("the frames").push(frame.message.kind());
                    let mut answer = Vec::new();
                    match frame.message {
                        Message::Hello if answering => {
                            let panel = Panel { width: 2, height: 2, format: PixelFormat::Rgb565 };
                            let info = BoardInfo {
                                panel,
                                max_scene: 4096,
                                profile: "scripted",
                                firmware: "scripted board",
                                capacities: Capacities::new(&[]),
                            };
                            Message::Board(info).encode(frame.tag, &mut answer).expect("encoded");
                        }
                        Message::Scene { pixels, .. } => {
                            let panel = Panel { width: 2, height: 2, format: PixelFormat::Rgb565 };
                            Message::Drawing { panel, pixels, frames: 0 }
                                .encode(frame.tag, &mut answer)
                                .expect("encoded");
                            *scene.lock().expect("the scene's tag") = Some(frame.tag);
                        }
                        _ => {}
                    }
                    let _ = std::io::Write::write_all(&mut controller, &answer);
                }
            }
        });
        ScriptedBoard { port, received, working }
    }

    /// The kinds of the frames that reached it so far.
    fn received(&self) -> Vec<Kind> {
        self.received.lock().expect("the frames").clone()
    }

    /// Waits until a frame of `kind` has reached it.
    fn wait_for(&self, kind: Kind) {
        let deadline = Instant::now() + HANG_GUARD;
        while !self.received().contains(&kind) {
            assert!(Instant::now() < deadline, "no {kind} reached the board: {:?}", self.received());
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

/// Moves the time slider to `frame` and waits for the draft (and the
/// render, if one is shown) to show it.
fn slide_to(browser: &Browser, frame: u32) {
    browser.run(&format!(
        "for (const id of {FRAME_PICTURES}) document.getElementById(id).dataset.frame = 'stale';
         const slider = document.getElementById('frame');
         slider.value = '{frame}'; slider.dispatchEvent(new Event('input')); return true;"
    ));
    let shown = format!("{FRAME_PICTURES}.every((id) => document.getElementById(id).dataset.frame === '{frame}')");
    browser.wait_for(&shown);
}

/// host-sim's picture of frame `frame` of the scene file `scene`:
/// `host-sim SCENE OUT.png --frame K [--size WxH]`.
fn host_frame(scene: &Path, frame: u32, size: Option<&str>) -> RgbImage {
    let dir = tempfile::tempdir().expect("a directory");
    let out = dir.path().join("frame.png");
    let frame = frame.to_string();
    let mut args = vec!["host-sim", scene.to_str().expect("a path"), out.to_str().expect("a path")];
    args.extend(["--frame", &frame, "--quiet"]);
    args.extend(size.iter().flat_map(|size| ["--size", size]));
    let (mut stdout, mut stderr) = (Vec::new(), Vec::new());
    let code = host_sim::cli::run(args, &mut stdout, &mut stderr);
    assert_eq!(code, 0, "{}", String::from_utf8_lossy(&stderr));
    octrace_images::formats::read(&std::fs::read(&out).expect("the frame")).expect("a PNG").to_rgb()
}

/// Runs `script` with `root`, the editor's shadow root, in scope.
fn in_editor(browser: &Browser, script: &str) -> serde_json::Value {
    browser.run(&format!("const root = document.getElementById('scene').shadowRoot; {script}"))
}

/// The page's pictures of a frame: the draft, and the render if one is shown.
const FRAME_PICTURES: &str = "['draft', ...(studio.lastRender ? ['image'] : [])]";
