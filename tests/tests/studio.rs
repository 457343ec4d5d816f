//! The scene studio (`host-sim studio`) in a real browser: Debian's
//! chromium, headless, driven over WebDriver by chromedriver. The page runs
//! octrace-core compiled to WebAssembly; these tests check that what it
//! shows is host-sim's image bit for bit, that a user can place, render and
//! save with the mouse, that "Send to board" shows a board's errors and
//! picture, that a render or draft of hours a pixel is stopped by the next
//! at once, and that the server keeps its security rules.
//!
//! The board is the software board, or the command `OCTRACE_BOARD_COMMAND` names
//! (as in tests/tests/board.rs: [`RunningBoard::for_tests`]).
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

#[test]
fn the_server_keeps_its_security_rules() {
    let dir = tempfile::tempdir().expect("a directory");
    let scene_path = dir.path().join("s.txt");
    std::fs::write(&scene_path, START).expect("written");
    std::fs::write(dir.path().join("secret.txt"), "secret").expect("written");
    let mut studio = Studio::start(Some(&scene_path));
    let port = studio.port;
    let token = format!("token={}", studio.token);
    let with_token = |path: &str| format!("{path}?{token}");

    // With the token and the right Host: the printed address leads to the
    // page under /TOKEN/, where its assets are too.
    let (status, head, _) = http_with_head(port, "GET", &with_token("/"), &[], b"");
    assert_eq!(status, 303, "{head}");
    assert!(head.lines().any(|l| l == format!("Location: /{}/", studio.token)), "{head}");
    let modules = [
        "/studio.js",
        "/octrace.js",
        "/editor.js",
        "/codemirror.js",
        "/keywords.js",
        "/model.js",
        "/view.js",
        "/tools.js",
        "/panel.js",
        "/board.js",
        "/render.js",
        "/time.js",
        "/worker.js",
        "/workers.js",
    ];
    for path in ["/", "/studio.css", "/octrace_studio.wasm"].into_iter().chain(modules) {
        let (status, head, body) = http_with_head(port, "GET", &format!("/{}{path}", studio.token), &[], b"");
        assert_eq!(status, 200, "{path}");
        assert!(!body.is_empty(), "{path}");
        // No cookie (a browser would send it to every port of 127.0.0.1),
        // no address in a Referer, nothing for other sites to embed.
        assert!(!head.to_ascii_lowercase().contains("set-cookie"), "{path}: {head}");
        for header in
            ["Referrer-Policy: no-referrer", "Cross-Origin-Resource-Policy: same-origin", "X-Frame-Options: DENY"]
        {
            assert!(head.lines().any(|l| l == header), "{path}: {header} in {head}");
        }
    }
    let (_, scene) = http(port, "GET", &with_token("/scene"), &[], b"");
    assert_eq!(scene, START.as_bytes());
    // The token also works as a header, but never as a cookie, and in the
    // path only for what the browser loads by address.
    assert_eq!(http(port, "GET", "/scene", &[("X-Studio-Token", &studio.token)], b"").0, 200);
    let cookie = format!("studio_token={}", studio.token);
    for (method, path) in [("GET", "/scene"), ("POST", "/board"), ("GET", "/studio.js")] {
        assert_eq!(http(port, method, path, &[("Cookie", &cookie)], b"RDEPTH 2\n").0, 403, "{method} {path}");
    }
    let in_path = format!("/{}/scene", studio.token);
    assert_eq!(http(port, "PUT", &in_path, &[("If-Match", "*")], b"RDEPTH 2\n").0, 403);
    assert_eq!(std::fs::read_to_string(&scene_path).unwrap(), START);

    // A browser's request for another site's page, even with the token:
    // refused (a page on another port of 127.0.0.1 is another origin, but
    // the same site).
    let other = format!("http://127.0.0.1:{}", port.wrapping_add(1));
    for foreign in [
        [("Origin", other.as_str()), ("Sec-Fetch-Site", "same-site")],
        [("Origin", "null"), ("Sec-Fetch-Site", "cross-site")],
        [("Origin", other.as_str()), ("X-Studio-Token", studio.token.as_str())],
        [("Sec-Fetch-Site", "same-site"), ("X-Studio-Token", studio.token.as_str())],
    ] {
        assert_eq!(http(port, "GET", &with_token("/scene"), &foreign, b"").0, 403, "{foreign:?}");
        assert_eq!(http(port, "PUT", &with_token("/scene"), &foreign, b"RDEPTH 2\n").0, 403, "{foreign:?}");
    }
    assert_eq!(std::fs::read_to_string(&scene_path).unwrap(), START);
    // Its own page's requests pass.
    let own = format!("http://127.0.0.1:{port}");
    let own_page = [("Origin", own.as_str()), ("Sec-Fetch-Site", "same-origin")];
    assert_eq!(http(port, "GET", &with_token("/scene"), &own_page, b"").0, 200);

    // No token, a wrong one: refused, even for the page.
    for path in ["/", "/scene", "/octrace_studio.wasm"] {
        assert_eq!(http(port, "GET", path, &[], b"").0, 403, "{path} without a token");
        assert_eq!(http(port, "GET", &format!("{path}?token=0123"), &[], b"").0, 403, "{path}, wrong token");
    }
    let wrong = "0".repeat(studio.token.len());
    assert_eq!(http(port, "GET", &format!("/?token={wrong}"), &[], b"").0, 403);
    assert_eq!(http(port, "PUT", "/scene", &[("If-Match", "*")], b"x").0, 403);
    // Without --board there is no board to send to (the rules come first);
    // asked which board, the answer is none.
    assert_eq!(http(port, "POST", "/board", &[], START.as_bytes()).0, 403);
    let (status, body) = http(port, "POST", &with_token("/board"), &[], START.as_bytes());
    assert_eq!(status, 404, "POST /board");
    assert!(String::from_utf8_lossy(&body).contains("without --board"), "{}", String::from_utf8_lossy(&body));
    assert_eq!(http(port, "GET", &with_token("/board"), &[], b""), (200, b"{\"port\":null}".to_vec()));

    // A foreign Host (DNS rebinding), even with the token.
    for host in [
        "evil.example:80",
        &format!("evil.example:{port}"),
        "127.0.0.1",
        &format!("127.0.0.1:{}", port.wrapping_add(1)),
    ] {
        assert_eq!(http(port, "GET", &with_token("/scene"), &[("Host", host)], b"").0, 421, "Host {host}");
    }
    assert_eq!(http(port, "GET", &with_token("/scene"), &[("Host", &format!("localhost:{port}"))], b"").0, 200);

    // Paths that try to leave the assets reach nothing.
    for path in [
        "/../secret.txt",
        "/%2e%2e/secret.txt",
        "/scene/../secret.txt",
        "//etc/passwd",
        "/studio.js/../../Cargo.toml",
        "/secret.txt",
        "/s.txt",
        "/assets/studio.js",
    ] {
        let (status, body) = http(port, "GET", &with_token(path), &[], b"");
        assert_eq!(status, 404, "{path}");
        assert!(!String::from_utf8_lossy(&body).contains("secret"), "{path}");
    }
    assert_eq!(http(port, "PUT", &with_token("/secret.txt"), &[("If-Match", "*")], b"x").0, 405);
    assert_eq!(std::fs::read_to_string(dir.path().join("secret.txt")).unwrap(), "secret");

    // A request refused is answered from its head: the body it announces is
    // never waited for nor held (16 MB announced, none sent, answered at
    // once; a body read first would have waited 10 s for it and said 400).
    // A head with a second Host, or token (a header's, the query's, or one
    // of each), is refused: the copy checked could differ from another one
    // read. A HEAD answer has no body.
    for head in [
        format!("PUT /scene HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Length: 16000000\r\n\r\n"),
        format!("GET /scene?{token} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nHost: evil.example\r\n\r\n"),
        format!(
            "GET /scene HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nX-Studio-Token: {}\r\nX-Studio-Token: x\r\n\r\n",
            studio.token
        ),
        format!("GET /scene?{token}&token=x HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n"),
        format!("GET /scene?{token} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nX-Studio-Token: x\r\n\r\n"),
        format!("HEAD /{}/ HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n", studio.token),
    ] {
        let mut stream = std::net::TcpStream::connect(("127.0.0.1", port)).expect("connects");
        std::io::Write::write_all(&mut stream, head.as_bytes()).expect("sent");
        let mut answer = Vec::new();
        std::io::Read::read_to_end(&mut stream, &mut answer).expect("answered");
        let answer = String::from_utf8_lossy(&answer);
        let (status_line, body) = answer.split_once("\r\n\r\n").expect("a head");
        let expected = match head.split(' ').next() {
            Some("PUT") => "HTTP/1.1 403",
            Some("HEAD") => "HTTP/1.1 200",
            _ => "HTTP/1.1 400",
        };
        assert!(status_line.starts_with(expected), "{head:?}: {answer}");
        if head.starts_with("HEAD") {
            assert!(body.is_empty() && !status_line.contains("Content-Length: 0\r\n"), "{answer}");
        }
    }

    // Saving: the version loaded, else a conflict; atomically.
    let (status, _) = http(port, "PUT", &with_token("/scene"), &[("If-Match", "\"0000000000000000\"")], b"X");
    assert_eq!(status, 409);
    assert_eq!(std::fs::read_to_string(&scene_path).unwrap(), START);
    // A private scene stays private.
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&scene_path, std::fs::Permissions::from_mode(0o600)).unwrap();
    assert_eq!(http(port, "PUT", &with_token("/scene"), &[("If-Match", "*")], b"RDEPTH 2\n").0, 200);
    assert_eq!(std::fs::read_to_string(&scene_path).unwrap(), "RDEPTH 2\n");
    assert_eq!(std::fs::metadata(&scene_path).unwrap().permissions().mode() & 0o777, 0o600);
    let leftovers: Vec<_> =
        std::fs::read_dir(dir.path()).unwrap().filter_map(|e| e.ok()).map(|e| e.file_name()).collect();
    assert_eq!(leftovers.len(), 2, "no temporary file left: {leftovers:?}");

    // Loopback only: the listening socket is bound to 127.0.0.1, not to
    // every interface.
    let tcp = std::fs::read_to_string("/proc/net/tcp").expect("/proc/net/tcp");
    let listening: Vec<&str> = tcp
        .lines()
        .skip(1)
        .filter_map(|l| {
            let fields: Vec<&str> = l.split_whitespace().collect();
            (fields.get(3) == Some(&"0A") && fields[1].ends_with(&format!(":{port:04X}"))).then_some(fields[1])
        })
        .collect();
    assert_eq!(listening, [format!("0100007F:{port:04X}")], "bound to 127.0.0.1 only");
    let tcp6 = std::fs::read_to_string("/proc/net/tcp6").unwrap_or_default();
    assert!(!tcp6.lines().any(|l| l.split_whitespace().nth(1).is_some_and(|a| a.ends_with(&format!(":{port:04X}")))));
    // And another address of this machine does not answer.
    if let Some(address) = std::net::UdpSocket::bind("0.0.0.0:0")
        .and_then(|s| s.connect("192.0.2.1:9").map(|_| s))
        .and_then(|s| s.local_addr())
        .ok()
        .filter(|a| !a.ip().is_loopback() && !a.ip().is_unspecified())
    {
        assert!(std::net::TcpStream::connect((address.ip(), port)).is_err(), "{} answers", address.ip());
    }

    // Ctrl-C stops it cleanly, and at once even while a browser holds an
    // idle connection open.
    let _idle = std::net::TcpStream::connect(("127.0.0.1", port)).expect("connects");
    let (status, stderr) = studio.interrupt();
    assert!(status.success(), "{status}: {stderr}");
    assert!(stderr.contains("stopped"), "{stderr}");
}

/// `--open` has the desktop's opener open a page that sends the browser
/// on: the token is on no command line (which any user may read), the page
/// is this user's alone, and it goes once the browser has come.
#[test]
fn open_puts_the_token_on_no_command_line() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().expect("a directory");
    // The opener: what it was given, the page's mode and text.
    let opener = dir.path().join("xdg-open");
    let seen = dir.path().join("seen");
    std::fs::write(
        &opener,
        format!(
            "#!/bin/sh\nprintf '%s\\n' \"$@\" > '{0}/args'\nstat -c %a \"$1\" > '{0}/mode'\ncat \"$1\" > '{0}/page'\ntouch '{1}'\n",
            dir.path().display(),
            seen.display()
        ),
    )
    .unwrap();
    std::fs::set_permissions(&opener, std::fs::Permissions::from_mode(0o755)).unwrap();
    let path = format!("{}:{}", dir.path().display(), std::env::var("PATH").unwrap_or_default());
    let studio = Studio::start_in(None, &[OsStr::new("--open")], &[("PATH", OsStr::new(&path))]);
    let deadline = Instant::now() + HANG_GUARD;
    while !seen.exists() {
        assert!(Instant::now() < deadline, "the opener never ran");
        std::thread::sleep(Duration::from_millis(20));
    }
    let read = |name: &str| std::fs::read_to_string(dir.path().join(name)).expect(name);
    let (args, page) = (read("args"), read("page"));
    assert!(!args.contains(&studio.token), "the token on the opener's command line: {args}");
    assert_eq!(read("mode").trim(), "600", "the page is its user's alone");
    assert!(page.contains(&studio.url), "the page sends the browser to the address: {page}");
    // The browser comes: the page goes.
    let launcher = PathBuf::from(args.trim());
    assert!(launcher.exists(), "{}", launcher.display());
    assert_eq!(http(studio.port, "GET", &format!("/?token={}", studio.token), &[], b"").0, 303);
    assert!(!launcher.exists(), "{} left behind", launcher.display());
}

#[test]
fn a_busy_port_is_an_error_not_a_panic() {
    let taken = std::net::TcpListener::bind("127.0.0.1:0").expect("a port");
    let port = taken.local_addr().unwrap().port();
    let out = children::output(Command::new(HOST_SIM).args(["studio", "--port", &port.to_string()])).expect("runs");
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot listen"), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn a_scene_that_cannot_be_read_is_an_error_at_start() {
    // A directory, as a render refuses it: nothing served.
    let dir = tempfile::tempdir().unwrap();
    let out = children::output(Command::new(HOST_SIM).arg("studio").arg(dir.path())).expect("runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains(&format!("studio: cannot read {}: Is a directory", dir.path().display())), "{stderr}");
    assert!(out.stdout.is_empty(), "nothing served: {}", String::from_utf8_lossy(&out.stdout));
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

#[test]
fn every_tool_places_its_object_and_selections_move_and_delete() {
    let dir = tempfile::tempdir().expect("a directory");
    let scene_path = dir.path().join("tools.txt");
    std::fs::write(&scene_path, START).expect("scene written");
    let studio = Studio::start(Some(&scene_path));
    let browser = Browser::start((1500, 900));
    browser.goto(&studio.url);
    browser.wait_for("document.body.dataset.ready === 'true'");

    // Keys 1–8 choose the tools; the sized ones take a point and a size.
    for (key, keyword) in [("2", "BOX 1 "), ("3", "SUPERQUADRIC 1 4 ")] {
        press(&browser, key);
        browser.drag("#wire", (-60, 60), (-60, 40));
        browser.drag("#wire", (0, 0), (20, 0));
        assert!(scene_text(&browser).contains(keyword), "{keyword} placed:\n{}", scene_text(&browser));
    }
    press(&browser, "4");
    for (x, y) in [(-40, 80), (40, 80), (0, 40)] {
        browser.drag("#wire", (x, y), (x, y - 10));
    }
    assert!(scene_text(&browser).contains("TRIANGLE 1 "));
    press(&browser, "5");
    browser.drag("#wire", (-30, 100), (-30, 90));
    browser.drag("#wire", (30, 130), (30, 130));
    assert!(scene_text(&browser).contains("RECTANGLE 1 "));
    press(&browser, "6");
    for (field, value) in [("order", 2), ("rows", 2), ("cols", 2), ("samples", 4)] {
        browser.run(&format!(
            "const i = document.querySelector('#panel input[data-field={field}]');
             i.value = '{value}'; i.dispatchEvent(new Event('change')); return true;"
        ));
    }
    for (x, y) in [(60, 60), (100, 60), (60, 100), (100, 100)] {
        browser.drag("#wire", (x, y), (x, y - 5));
    }
    assert!(scene_text(&browser).contains("BSPLINE 1 2 2 2 4 4"), "{}", scene_text(&browser));
    press(&browser, "8");
    browser.drag("#wire", (-100, 0), (-100, -40));
    assert_eq!(scene_text(&browser).matches("LIGHT ").count(), 2);
    press(&browser, "7");
    browser.drag("#wire", (0, 150), (0, 120));
    assert!(!scene_text(&browser).contains("VIEWPOINT 0 4 12"), "the eye moved");
    assert_eq!(scene_text(&browser).matches("VIEWPOINT").count(), 1);
    // Everything placed is a valid scene, and the page renders it as
    // host-sim does.
    assert!(browser.run("return document.querySelectorAll('#errors li').length;") == 0, "{}", scene_text(&browser));
    render_and_wait(&browser);
    let text = scene_text(&browser);
    assert_same("placed objects", browser.canvas_rgb("image"), &host_render(&text, None).image);

    // Select the box by its centre, drag it along the x–z plane, delete it.
    press(&browser, "s");
    let centre = browser.run(
        "const s = studio.model.find((s) => s.keyword === 'BOX');
         const q = studio.project(s.args.slice(1, 4)); const c = document.getElementById('wire');
         return [Math.round(q[0] - c.width / 2), Math.round(q[1] - c.height / 2)];",
    );
    let (x, y) = (centre[0].as_i64().unwrap(), centre[1].as_i64().unwrap());
    let before: String = text.lines().find(|l| l.starts_with("BOX")).unwrap().into();
    browser.drag("#wire", (x, y), (x + 30, y + 10));
    let after: String = scene_text(&browser).lines().find(|l| l.starts_with("BOX")).unwrap().into();
    assert_ne!(before, after, "the box moved");
    assert_eq!(before.split(' ').nth(5), after.split(' ').nth(5), "sizes kept");
    // The panel edits the selection's numbers.
    browser.run(
        "const i = document.querySelector('#panel input[data-field=\"half x\"]');
         i.value = '0.75'; i.dispatchEvent(new Event('change')); return true;",
    );
    assert!(scene_text(&browser).lines().any(|l| l.starts_with("BOX") && l.split(' ').nth(5) == Some("0.75")));
    press(&browser, "\u{E017}"); // Delete
    assert!(!scene_text(&browser).contains("BOX"), "deleted");
    // Undo (Ctrl+Z) brings it back.
    press(&browser, "\u{E009}z\u{E009}");
    assert!(scene_text(&browser).contains("BOX"), "undone");

    // An image file loads into the display; Clear empties it; help opens.
    let image = octrace_images::formats::Image::Rgb(host_render(&text, Some((20, 10))).image);
    let file = dir.path().join("picture.tga");
    let mut bytes = Vec::new();
    octrace_images::formats::write(&image, octrace_images::formats::Format::Tga, &mut bytes).expect("encoded");
    std::fs::write(&file, bytes).expect("written");
    browser.type_into("#load-image", &file.display().to_string());
    browser.wait_for("document.getElementById('image').dataset.state === 'loaded'");
    assert_same("loaded Targa", browser.canvas_rgb("image"), &image.to_rgb());
    browser.click("#clear");
    assert_eq!(browser.run("return document.getElementById('image').dataset.state;"), "clear");
    press(&browser, "\u{E031}"); // F1
    assert_eq!(browser.run("return document.getElementById('help').open;"), true);
}

/// Runs `script` with `root`, the editor's shadow root, in scope.
fn in_editor(browser: &Browser, script: &str) -> serde_json::Value {
    browser.run(&format!("const root = document.getElementById('scene').shadowRoot; {script}"))
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

/// The editor as people expect one: line numbers, long lines whole
/// (scrolled, never wrapped), the format's keywords highlighted — the
/// core's list (host-sim makes the page's keywords.js from it), every
/// keyword and nothing else — each error marked at its line and column, one
/// undo history for typing and the tools' edits, the page's keys in it,
/// and nothing the page's Content-Security-Policy refuses.
#[test]
fn the_editor_highlights_the_cores_keywords_marks_errors_and_keeps_one_history() {
    let studio = Studio::start(None);
    let browser = Browser::start((1500, 900));
    browser.goto(&studio.url);
    browser.wait_for("document.body.dataset.ready === 'true'");

    // Every keyword of the core, in either ASCII case, beside words that
    // are none: in a comment, quoted, plural, with a non-ASCII letter that
    // upper-cases to S.
    let keywords: Vec<&str> = octrace_core::parse::statement_arities().map(|(keyword, _)| keyword).collect();
    let mut text = String::from("/* SPHERE */ \"BOX\" SPHERES \u{17f}PHERE 1.5e3 -.5 1.2.3 // LIGHT\n");
    for (i, keyword) in keywords.iter().enumerate() {
        text += &if i % 2 == 0 { keyword.to_ascii_lowercase() } else { keyword.to_string() };
        text += "\n";
    }
    set_text(&browser, &text);
    let highlighted: Vec<String> =
        editor_texts(&browser, ".tok-keyword").iter().map(|k| k.to_ascii_uppercase()).collect();
    assert_eq!(highlighted, keywords);
    assert_eq!(editor_texts(&browser, ".tok-comment"), ["/* SPHERE */", "// LIGHT"]);
    assert_eq!(editor_texts(&browser, ".tok-string"), ["\"BOX\""]);
    assert_eq!(editor_texts(&browser, ".tok-number"), ["1.5e3", "-.5"]);
    // Line numbers, one a line.
    let numbers = editor_texts(&browser, ".cm-lineNumbers .cm-gutterElement");
    for line in 1..=keywords.len() + 1 {
        assert!(numbers.contains(&line.to_string()), "line {line} is numbered: {numbers:?}");
    }
    // A long line stays one line: as high as a short one, scrolled sideways.
    set_text(&browser, &format!("RDEPTH 2\nBACKGROUND {}\n", "0.5 ".repeat(120)));
    let lines = in_editor(
        &browser,
        "const lines = [...root.querySelectorAll('.cm-line')].map((l) => l.getBoundingClientRect().height);
         const scroller = root.querySelector('.cm-scroller');
         return [lines[0], lines[1], scroller.scrollWidth > scroller.clientWidth];",
    );
    assert_eq!((&lines[0], &lines[2]), (&lines[1], &true.into()), "no soft wrapping: {lines}");

    // Each error marked where the core says it is, a MOVE's too, and listed.
    let text = "VIEWPOINT 0 0 5\nSPHERE 1 x 0 0 0\nFRAMES 3\nLIGHT 1 0 0 0 MOVE 0 1 1 1 MOVE 1 2 2 2\n\
                LIGHT 1 0 0 0 MOVE 0 1 1 1  1 q 0 0\n";
    set_text(&browser, text);
    let listed = browser
        .run("return [...document.querySelectorAll('#errors li')].map((li) => [li.dataset.line, li.dataset.column]);");
    let listed: Vec<(String, String)> = serde_json::from_value(listed).expect("the errors");
    let at: Vec<(usize, usize)> = listed.iter().map(|(l, c)| (l.parse().unwrap(), c.parse().unwrap())).collect();
    assert_eq!(at, [(2, 10), (4, 28), (5, 31)], "{listed:?}");
    let words: Vec<String> = at
        .iter()
        .map(|&(line, column)| {
            let line = text.lines().nth(line - 1).expect("a line");
            line.chars().skip(column - 1).take_while(|c| !c.is_whitespace()).collect()
        })
        .collect();
    assert_eq!(words, ["x", "MOVE", "q"]);
    let marked = in_editor(
        &browser,
        "const lines = [...root.querySelectorAll('.cm-line')];
         return [...root.querySelectorAll('.cm-lintRange-error')].map((e) => [lines.indexOf(e.closest('.cm-line')) + 1, e.textContent]);",
    );
    assert_eq!(marked, serde_json::json!([[2, "x"], [4, "MOVE"], [5, "q"]]));
    assert_eq!(editor_texts(&browser, ".cm-gutter-lint .cm-lint-marker-error").len(), 3, "a mark in the gutter a line");

    // One history: typing, then a tool's edit (the panel's background),
    // undone in turn by Ctrl+Z outside the editor, and redone by Ctrl+Y.
    set_text(&browser, START);
    let content = browser.run("return studio.editor.view.contentDOM;");
    browser.type_into_element(&content, "RDEPTH 2");
    let typed = scene_text(&browser);
    assert!(typed.starts_with(START) && typed.contains("RDEPTH 2"), "{typed}");
    press(&browser, "\u{E00C}"); // Escape: the scene's panel
                                 // Its lights are numbered among the lights, not among the statements.
    let lights = browser.run(
        "return [...document.querySelectorAll('#panel input')].map((i) => i.dataset.field)
           .filter((f) => f.startsWith('light'));",
    );
    assert_eq!(lights, serde_json::json!(["light 1 brightness"]));
    browser.run(
        "const i = document.querySelector('#panel input[data-field=\"background r\"]');
         i.value = '0.5'; i.dispatchEvent(new Event('change')); return true;",
    );
    let edited = scene_text(&browser);
    assert!(edited.contains("BACKGROUND 0.5 0.1 0.15"), "{edited}");
    press(&browser, "\u{E009}z\u{E009}");
    assert_eq!(scene_text(&browser), typed, "the panel's edit undone");
    press(&browser, "\u{E009}z\u{E009}");
    assert_eq!(scene_text(&browser), START, "the typing undone");
    press(&browser, "\u{E009}y\u{E009}");
    assert_eq!(scene_text(&browser), typed, "the typing redone");
    browser.click("#redo");
    assert_eq!(scene_text(&browser), edited, "the panel's edit redone");

    // Ctrl+Enter in the editor renders, and adds no line.
    browser.run("studio.editor.view.focus(); document.getElementById('image').dataset.state = 'stale'; return true;");
    browser.keys("\u{E009}\u{E007}\u{E009}");
    browser.wait_for("document.getElementById('image').dataset.state === 'done'");
    assert_eq!(scene_text(&browser), edited);
    assert_eq!(page_log(&browser), serde_json::json!([]), "nothing refused, no script error");
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

/// The page's pictures of a frame: the draft, and the render if one is shown.
const FRAME_PICTURES: &str = "['draft', ...(studio.lastRender ? ['image'] : [])]";

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

/// The share of the render's pixels the page says it traced for its frame.
fn traced_share(browser: &Browser) -> f64 {
    let status = browser.run("return document.getElementById('status').textContent;");
    let status = status.as_str().expect("a status");
    let share = status.split(", ").nth(1).and_then(|s| s.split(' ').next()).and_then(|n| n.parse().ok());
    share.unwrap_or_else(|| panic!("a share of pixels traced in {status:?}"))
}

/// Plays the page's animation for 30 frames, then pauses; returns the frame
/// it stopped at, once shown. Prints how fast `what` played.
fn play_and_pause(browser: &Browser, what: &str) -> u32 {
    let start = browser.run("return studio.frame;").as_u64().expect("a frame");
    browser.click("#play");
    browser.wait_for("studio.played && studio.played.length >= 30");
    browser.click("#play");
    let shown =
        format!("{FRAME_PICTURES}.every((id) => document.getElementById(id).dataset.frame === String(studio.frame))");
    browser.wait_for(&format!("!studio.playing && {shown}"));
    let frame = browser.run("return studio.frame;").as_u64().expect("a frame");
    let played = browser.run("return studio.played;");
    let played = played.as_array().expect("the frames played");
    let frames: Vec<u64> = played.iter().map(|p| p["frame"].as_u64().expect("a frame")).collect();
    let in_turn: Vec<u64> = (1..=frames.len() as u64).map(|i| (start + i) % 48).collect();
    assert_eq!(frames, in_turn, "every frame in turn");
    assert_eq!(frame, in_turn[in_turn.len() - 1], "paused at the last frame played");
    // The first frame is traced whole (with the tracker's search of the
    // loop); the others re-trace what moved.
    let mut ms: Vec<f64> = played.iter().skip(1).map(|p| p["ms"].as_f64().expect("ms")).collect();
    let mut shares: Vec<f64> = played.iter().skip(1).map(|p| p["share"].as_f64().expect("a share")).collect();
    ms.sort_by(f64::total_cmp);
    shares.sort_by(f64::total_cmp);
    let shown = |i: usize| played[i]["at"].as_f64().expect("a time");
    let rate = 1000.0 * (played.len() - 2) as f64 / (shown(played.len() - 1) - shown(1));
    println!(
        "anim_fig5_1 played, {what}: {} frames at {rate:.1} a second; the first in {:.1} ms, the others each in \
         {:.1} ms (median; slowest {:.1} ms), {:.1} % of the draft's pixels traced (median)",
        played.len(),
        played[0]["ms"].as_f64().expect("ms"),
        ms[ms.len() / 2],
        ms[ms.len() - 1],
        shares[shares.len() / 2]
    );
    frame as u32
}

/// An animation in the studio: the time controls show for a scene with
/// FRAMES and not for a still; the frame of the slider is what the render
/// and the draft show, host-sim's `--frame K` picture bit for bit, reached
/// forward (re-tracing only what moved), by a jump, backwards or round the
/// loop; the wireframe and the tools see the objects where they are at that
/// frame; play goes through the frames in turn, and where it stops is
/// host-sim's frame too; an error of one frame only (the eye moved onto the
/// point looked at) is marked at its MOVE when that frame is shown.
#[test]
fn the_time_slider_and_play_show_host_sims_frames() {
    let dir = tempfile::tempdir().expect("a directory");
    let scene = dir.path().join("anim_fig5_1.txt");
    std::fs::copy(scene_path("anim_fig5_1"), &scene).expect("copied");
    let studio = Studio::start(Some(&scene));
    let browser = Browser::start((1500, 900));
    browser.goto(&studio.url);
    browser.wait_for("document.body.dataset.ready === 'true'");
    let controls =
        browser.run("return [document.getElementById('time').hidden, document.getElementById('frame').max];");
    assert_eq!(controls, serde_json::json!([false, "47"]));

    // Play the draft alone, then pause: the frames went by in turn, and
    // the draft shows host-sim's frame.
    browser.wait_for("document.getElementById('draft').dataset.state === 'done'");
    let frame = play_and_pause(&browser, "the draft (160x120)");
    let draft = host_frame(&scene, frame, Some("160x120"));
    assert_same(&format!("draft of frame {frame}, played to"), browser.canvas_rgb("draft"), &draft);
    slide_to(&browser, 0);
    // What the page's module takes for a draft of each frame: traced whole,
    // and by its player, twice round the loop (loading and indexing the
    // frame included; printed for BENCHMARKS.md).
    let timed = browser.run(
        "const octrace = studio.octrace, text = studio.editor.text(), whole = [], played = [];
         const time = (k, trace) => { const t = performance.now(); octrace.load(text, k); octrace.prepare(0, 160, 120);
                                      trace(); return performance.now() - t; };
         for (let k = 0; k < 48; k++) whole.push(time(k, () => octrace.render(0, 0, 160, 120)));
         for (let k = 0; k < 96; k++) played.push(time(k % 48, () => octrace.traceFrame()));
         const median = (all) => all.slice().sort((a, b) => a - b)[all.length >> 1];
         return [median(whole), played[0], median(played.slice(1))];",
    );
    println!(
        "anim_fig5_1's draft (160x120) in the page's module: a frame traced whole in {:.1} ms (median), \
         by the player the first in {:.1} ms, the others in {:.1} ms (median)",
        timed[0].as_f64().expect("ms"),
        timed[1].as_f64().expect("ms"),
        timed[2].as_f64().expect("ms")
    );

    // Frame 0, rendered as any scene is (parallel tiles), and its draft.
    render_and_wait(&browser);
    assert_same("frame 0", browser.canvas_rgb("image"), &host_frame(&scene, 0, None));
    browser.wait_for("document.getElementById('draft').dataset.state === 'done'");
    assert_same("draft of frame 0", browser.canvas_rgb("draft"), &host_frame(&scene, 0, Some("160x120")));
    // Then frames forward (re-tracing a small share), a jump, backwards,
    // and round the loop from the last frame to the first.
    for (frame, forward) in [(1, false), (2, true), (30, false), (29, false), (47, false), (0, true)] {
        slide_to(&browser, frame);
        let share = traced_share(&browser);
        assert!(!forward || share < 50.0, "frame {frame}: {share} % of the pixels traced");
        assert_same(&format!("frame {frame}"), browser.canvas_rgb("image"), &host_frame(&scene, frame, None));
        let draft = host_frame(&scene, frame, Some("160x120"));
        assert_same(&format!("draft of frame {frame}"), browser.canvas_rgb("draft"), &draft);
    }

    // Play with the render shown, then pause: the frame shown is host-sim's.
    let frame = play_and_pause(&browser, "the render (240x180) and the draft (160x120)");
    assert_same(&format!("frame {frame}, played to"), browser.canvas_rgb("image"), &host_frame(&scene, frame, None));
    let draft = host_frame(&scene, frame, Some("160x120"));
    assert_same(&format!("draft of frame {frame}, played to"), browser.canvas_rgb("draft"), &draft);
    screenshot(&browser, "studio");

    // A render asked for while playing stops the player and stays: the
    // frame shown then, whole, not replaced by a frame the player was
    // still tracing.
    browser.click("#play");
    browser.wait_for("studio.played && studio.played.length >= 3");
    render_and_wait(&browser);
    let frame = browser.run("return studio.frame;").as_u64().expect("a frame") as u32;
    // Time for a frame the player traced to come, were it still shown.
    std::thread::sleep(std::time::Duration::from_millis(500));
    assert_eq!(browser.run("return [studio.playing, studio.frame];"), serde_json::json!([false, frame]));
    let image = browser.canvas_rgb("image");
    assert_same(&format!("frame {frame}, rendered while playing"), image, &host_frame(&scene, frame, None));

    // The wireframe shows the red sphere where frame 10 has it (its MOVE's
    // second key: 0.3 left of and 3 behind where it is written), and the
    // select tool picks it there.
    let wire_at = |frame: u32| {
        slide_to(&browser, frame);
        browser.run("return document.getElementById('wire').toDataURL();")
    };
    let (at_0, at_10) = (wire_at(0), wire_at(10));
    assert!(at_0 != at_10, "the wireframe follows the frame");
    assert!(wire_at(0) == at_0, "the wireframe at frame 0 again");
    wire_at(10);
    press(&browser, "s");
    let there = browser.run(
        "const q = studio.project([-2.6 - 0.3, 0.3, 0.6 - 3.0]); const c = document.getElementById('wire');
         return [Math.round(q[0] - c.width / 2), Math.round(q[1] - c.height / 2)];",
    );
    let (x, y) = (there[0].as_i64().expect("x"), there[1].as_i64().expect("y"));
    browser.drag("#wire", (x, y), (x, y));
    let picked = browser.run("const s = studio.model[studio.selection]; return s && [s.keyword, s.args[1]];");
    assert_eq!(picked, serde_json::json!(["SPHERE", 1.3]), "the red sphere, picked where it is at frame 10");

    // An error at one frame only: the eye moves onto the point looked at
    // at frame 2. Every frame's camera is checked as the text loads, so the
    // page marks it at the MOVE whichever frame is shown (frame 0 here).
    slide_to(&browser, 0);
    set_text(
        &browser,
        "FRAMES 3\nORIGIN 0 0 0\nVIEWPOINT 0 0 5 MOVE 0 0 0 0  2 0 0 -5\nLIGHT 5 3 3 3\n\
         SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nSPHERE 1 1 0 0 -9\n",
    );
    browser.wait_for(
        "[...document.querySelectorAll('#errors li')].some((li) => li.textContent.startsWith('3:17: ') \
         && li.textContent.includes('frame 2'))",
    );
    assert_eq!(editor_texts(&browser, ".cm-lintRange-error"), ["MOVE"]);

    // A still scene hides the controls.
    set_text(&browser, START);
    assert_eq!(browser.run("return document.getElementById('time').hidden;"), true);
    assert_eq!(page_log(&browser), serde_json::json!([]), "nothing refused, no script error");
}

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

/// A page of another program on this machine, served from another port of
/// 127.0.0.1 (another origin, but the same site to a browser: ports do not
/// separate sites). It tries the studio's `/board` and `/scene` with all a
/// browser adds on its own: a form's POST (whose text/plain body is a valid
/// scene, `RDEPTH 2 /*=*/`) and fetches with credentials. Returns its
/// port, and the head of every request it got.
fn hostile_page(studio_port: u16) -> (u16, std::sync::Arc<std::sync::Mutex<Vec<String>>>) {
    let studio = format!("http://127.0.0.1:{studio_port}");
    let page = format!(
        r#"<!doctype html><html><body>
<iframe name="sink"></iframe>
<form id="form" method="POST" action="{studio}/board" enctype="text/plain" target="sink">
<input type="hidden" name="RDEPTH 2 /*" value="*/"></form>
<script>
const results = {{}};
const attempt = async (name, url, init) => {{
  try {{ const r = await fetch(url, init); results[name] = r.type + ' ' + r.status; }}
  catch (e) {{ results[name] = 'refused: ' + e.name; }}
}};
document.getElementById('form').submit();
(async () => {{
  await attempt('POST /board', '{studio}/board', {{ method: 'POST', body: 'RDEPTH 2\n', mode: 'no-cors', credentials: 'include' }});
  await attempt('GET /scene', '{studio}/scene', {{ credentials: 'include' }});
  await attempt('GET /scene, no-cors', '{studio}/scene', {{ mode: 'no-cors', credentials: 'include' }});
  await attempt('PUT /scene', '{studio}/scene', {{ method: 'PUT', body: 'RDEPTH 3\n', headers: {{ 'If-Match': '*' }}, credentials: 'include' }});
  await attempt('POST /board, a guessed token', '{studio}/board', {{ method: 'POST', body: 'RDEPTH 2\n', headers: {{ 'X-Studio-Token': '0123' }} }});
  document.body.dataset.results = JSON.stringify(results);
}})();
</script></body></html>"#
    );
    let listener = std::net::TcpListener::bind("127.0.0.1:0").expect("a port");
    let port = listener.local_addr().expect("an address").port();
    let requests = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let seen = std::sync::Arc::clone(&requests);
    std::thread::spawn(move || {
        for stream in listener.incoming() {
            let Ok(mut stream) = stream else { continue };
            let mut head = Vec::new();
            let mut byte = [0u8];
            while !head.ends_with(b"\r\n\r\n") && std::io::Read::read(&mut stream, &mut byte).is_ok_and(|n| n == 1) {
                head.push(byte[0]);
            }
            let head = String::from_utf8_lossy(&head).into_owned();
            let body = if head.starts_with("GET / ") { page.as_str() } else { "" };
            let status = if body.is_empty() { "404 Not Found" } else { "200 OK" };
            let response = format!(
                "HTTP/1.1 {status}\r\nContent-Type: text/html\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
                body.len()
            );
            let _ = std::io::Write::write_all(&mut stream, response.as_bytes());
            seen.lock().expect("the requests").push(head);
        }
    });
    (port, requests)
}

#[test]
fn another_local_page_cannot_drive_the_studio_nor_learn_its_token() {
    let board = ScriptedBoard::start(true);
    let board_port = board.port.clone();
    let dir = tempfile::tempdir().expect("a directory");
    let scene_path = dir.path().join("s.txt");
    std::fs::write(&scene_path, START).expect("written");
    let mut studio = Studio::start_with(Some(&scene_path), &["--board".as_ref(), board_port.as_os_str()]);
    let (page_port, requests) = hostile_page(studio.port);
    assert_ne!(page_port, studio.port);
    // The user has the studio open; then the browser shows the other page.
    let browser = Browser::start((1200, 800));
    browser.goto(&studio.url);
    browser.wait_for("document.body.dataset.ready === 'true'");
    browser.goto(&format!("http://127.0.0.1:{page_port}/"));
    browser.wait_for("document.body.dataset.results");
    let results = browser.run("return document.body.dataset.results;");
    // The form's POST went when the page loaded: once the studio has
    // refused it and the fetch (and said so), nothing of them is on its way.
    let refused = |log: &str, what: &str| {
        log.lines().filter(|l| l.contains(&format!("refused {what} from another site"))).count()
    };
    studio.wait_for_log("both refusals of POST /board", |log| refused(log, "POST /board") >= 2);

    // Nothing reached the board, the scene is as it was, and the other
    // page's server never saw the token.
    assert!(board.received().is_empty(), "a request of the other page reached the board: {results}");
    assert_eq!(std::fs::read_to_string(&scene_path).unwrap(), START, "{results}");
    let requests = requests.lock().expect("the requests").clone();
    assert!(!requests.is_empty(), "the other page was served");
    for head in &requests {
        assert!(!head.contains(&studio.token), "the studio's token went to another server:\n{head}");
    }
    // The studio refused them, and said so.
    let (_, stderr) = studio.interrupt();
    assert!(refused(&stderr, "POST /board") >= 2, "the form and the fetch: {results}\n{stderr}");
    assert!(refused(&stderr, "GET /scene") >= 2, "both fetches: {results}\n{stderr}");
    assert!(stderr.contains(&format!("(Origin http://127.0.0.1:{page_port})")), "{stderr}");
    // The fetches that needed the studio's leave (a PUT, a header) got none.
    let results: serde_json::Value = serde_json::from_str(results.as_str().expect("JSON")).expect("results");
    for name in ["GET /scene", "PUT /scene", "POST /board, a guessed token"] {
        assert!(results[name].as_str().is_some_and(|r| r.starts_with("refused")), "{name}: {results}");
    }
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
