//! `host-sim studio`: a small HTTP/1.1 server on 127.0.0.1 for the scene
//! studio page, which runs octrace-core compiled to WebAssembly.
//!
//! Invariants (the security rules): the listener is bound to 127.0.0.1
//! only, and handles 32 connections at once at most (beyond them the one
//! not yet admitted that came first is closed); a request is admitted
//! from its head alone, its body read only then; a request whose Host is
//! not this address and port is refused (DNS
//! rebinding); a request a browser sends for another site's page (its
//! `Origin` not this server's, or `Sec-Fetch-Site` neither `same-origin`
//! nor `none`) is refused, and said on stderr; every request carries the
//! session's token, never in a cookie (a browser sends cookies to every
//! port of a host): the page and its assets are loaded under `/TOKEN/`
//! (what the browser loads by address), and everything else gives it in
//! `X-Studio-Token` (the page's own requests) or `?token=`; the only file
//! ever read or written is the scene file named on the command line,
//! through `GET`/`PUT /scene`, and every other path is an embedded asset
//! or 404 — no request path reaches the file system; no `GET` changes
//! anything; the only serial port opened is the one `--board` names,
//! through `POST /board`; the token is on no command line (`--open` gives
//! the desktop's opener a page only this user may read).

mod board;
mod http;

use crate::board::Waits;
use crate::exit::{CliError, ShownPath};
use crate::output::write_atomically;
use crate::terminal::shown;
use board::BoardSender;
use http::{Request, Response};
use std::io::{BufReader, Read, Write};
use std::net::{Ipv4Addr, SocketAddr, TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// Arguments of `host-sim studio`.
#[derive(clap::Args, Debug)]
pub struct StudioArgs {
    /// The scene file to edit (the only file the studio reads or writes);
    /// created on the first save if it does not exist. Without one, the
    /// studio starts from an example scene and cannot save it.
    pub scene: Option<PathBuf>,
    /// The port to listen on (127.0.0.1 only); 0 or none: any free port.
    #[arg(long, default_value_t = 0)]
    pub port: u16,
    /// Also open the page in the desktop's browser.
    #[arg(long)]
    pub open: bool,
    /// The serial port of a board running octrace's live firmware: the page
    /// gains "Send to board", which this server sends as `host-sim board
    /// --check` does (errors at their line and column, or the picture and
    /// whether it is host-sim's).
    #[arg(long, value_name = "PORT")]
    pub board: Option<PathBuf>,
    /// Seconds a send may take at most: the board's hello, the scene, and
    /// its answer (every error, or every row of the drawing). Without it,
    /// as `host-sim board`: a board is followed as long as it keeps
    /// drawing, and given up when it says nothing for 8 s (120 s while it
    /// loads a scene).
    #[arg(long, value_name = "SECONDS", value_parser = clap::value_parser!(u64).range(1..=86_400))]
    pub board_timeout: Option<u64>,
    /// As `host-sim board --patience`: wait N times as long for a board
    /// that says nothing (for the emulated Pico on a busy machine).
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1_000))]
    pub board_patience: u32,
}

/// The page, its script and style, and the WebAssembly module, built into
/// the binary (the module by `build.rs`; `codemirror.js`, the editor, is
/// CodeMirror 6 bundled by `studio/editor/build.mjs` and committed). The
/// keywords' module is made from the core's list (`keywords_module`).
const ASSETS: [(&str, &str, &[u8]); 16] = [
    ("/", "text/html; charset=utf-8", include_bytes!("assets/index.html")),
    ("/studio.js", "text/javascript; charset=utf-8", include_bytes!("assets/studio.js")),
    ("/editor.js", "text/javascript; charset=utf-8", include_bytes!("assets/editor.js")),
    ("/codemirror.js", "text/javascript; charset=utf-8", include_bytes!("assets/codemirror.js")),
    ("/time.js", "text/javascript; charset=utf-8", include_bytes!("assets/time.js")),
    ("/octrace.js", "text/javascript; charset=utf-8", include_bytes!("assets/octrace.js")),
    ("/model.js", "text/javascript; charset=utf-8", include_bytes!("assets/model.js")),
    ("/view.js", "text/javascript; charset=utf-8", include_bytes!("assets/view.js")),
    ("/tools.js", "text/javascript; charset=utf-8", include_bytes!("assets/tools.js")),
    ("/panel.js", "text/javascript; charset=utf-8", include_bytes!("assets/panel.js")),
    ("/board.js", "text/javascript; charset=utf-8", include_bytes!("assets/board.js")),
    ("/render.js", "text/javascript; charset=utf-8", include_bytes!("assets/render.js")),
    ("/workers.js", "text/javascript; charset=utf-8", include_bytes!("assets/workers.js")),
    ("/worker.js", "text/javascript; charset=utf-8", include_bytes!("assets/worker.js")),
    ("/studio.css", "text/css; charset=utf-8", include_bytes!("assets/studio.css")),
    ("/octrace_studio.wasm", "application/wasm", include_bytes!(concat!(env!("OUT_DIR"), "/octrace_studio.wasm"))),
];

/// The scene shown when the studio is started without a file.
const EXAMPLE_SCENE: &str = include_str!("../../../scenes/fig5_1.txt");

/// The most a saved scene may be (the largest scene in `scenes/` is far
/// smaller).
const MAX_SCENE_BYTES: usize = 16 << 20;

/// What every connection handler shares.
struct Shared {
    token: String,
    /// The Host values accepted: `127.0.0.1:PORT` and `localhost:PORT`.
    hosts: [String; 2],
    scene: Option<PathBuf>,
    /// Held while the scene file is compared and replaced, so two saves
    /// cannot interleave.
    saving: Mutex<()>,
    /// The board `--board` names.
    board: Option<BoardSender>,
    /// The file `--open` had the browser open (see [`open_browser`]),
    /// until the browser has come.
    launcher: Mutex<Option<PathBuf>>,
}

impl Shared {
    /// Removes the file `--open` gave the browser, if it is still there.
    fn forget_launcher(&self) {
        if let Some(path) = self.launcher.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).take() {
            let _ = std::fs::remove_file(path);
        }
    }
}

/// Runs the studio until Ctrl-C; fails before serving anything if it cannot
/// listen or make its token.
pub fn run(args: &StudioArgs, stdout: &mut dyn Write, stderr: &mut dyn Write) -> Result<(), CliError> {
    let board = match &args.board {
        None => None,
        Some(port) if crate::board::is_port(port) => {
            let name = port.display().to_string();
            // Opened once now, as each Send opens it: a device that is no
            // serial line (`/dev/null`) is refused at start, not at the
            // first Send.
            let waits = Waits { cap: args.board_timeout.map(Duration::from_secs), patience: args.board_patience };
            crate::board::BoardLink::open(&name, waits)
                .map_err(|e| CliError::Invalid(format!("studio: --board {}: {e}", shown(&name))))?;
            Some(BoardSender::new(name, waits))
        }
        Some(port) => {
            let _ = writeln!(stderr, "host-sim studio: the serial ports:");
            let _ = crate::board::write_ports(stderr);
            return Err(CliError::Invalid(format!(
                "studio: --board {} is no serial port: give the port of a board running octrace's live firmware",
                ShownPath(port)
            )));
        }
    };
    // A scene file that cannot be read (a directory, a file without the
    // permission) is refused at start, as a render refuses it; one that
    // does not exist yet is made by the first save.
    if let Some(path) = &args.scene {
        read_scene(path).map_err(|e| CliError::Io(format!("studio: cannot read {}: {e}", ShownPath(path))))?;
    }
    let listener = TcpListener::bind(SocketAddr::from((Ipv4Addr::LOCALHOST, args.port)))
        .map_err(|e| CliError::Io(format!("studio: cannot listen on 127.0.0.1:{}: {e}", args.port)))?;
    let port = listener.local_addr().map_err(|e| CliError::Io(format!("studio: {e}")))?.port();
    let token = new_token().map_err(|e| CliError::Io(format!("studio: no randomness for the token: {e}")))?;
    let url = format!("http://127.0.0.1:{port}/?token={token}");
    let shared = Arc::new(Shared {
        token,
        hosts: [format!("127.0.0.1:{port}"), format!("localhost:{port}")],
        scene: args.scene.clone(),
        saving: Mutex::new(()),
        board,
        launcher: Mutex::new(None),
    });
    let _ = writeln!(stdout, "{url}");
    let _ = stdout.flush();
    match &args.scene {
        Some(path) if !path.exists() => {
            let _ = writeln!(
                stderr,
                "host-sim studio: editing {}, a new file: created on the first save (Ctrl-C stops)",
                ShownPath(path)
            );
        }
        Some(path) => {
            let _ = writeln!(stderr, "host-sim studio: editing {} (Ctrl-C stops)", ShownPath(path));
        }
        None => {
            let _ = writeln!(stderr, "host-sim studio: no scene file given: an example, not saved (Ctrl-C stops)");
        }
    }
    if let Some(board) = &shared.board {
        let _ = writeln!(stderr, "host-sim studio: \"Send to board\" sends to the board at {}", shown(board.port()));
    }
    if args.open {
        *shared.launcher.lock().unwrap_or_else(|poisoned| poisoned.into_inner()) = open_browser(&url, stderr);
    }
    // Ctrl-C, SIGTERM or SIGHUP: a save under way ends first.
    serve(&listener, &shared, crate::signals::stop_flag());
    shared.forget_launcher();
    let _ = writeln!(stderr, "host-sim studio: stopped");
    Ok(())
}

/// Accepts connections until `stop` is set, each on its own thread. On
/// stop it waits only for a save under way (so the scene file is never
/// left half-replaced); a connection a browser keeps open idle does not
/// hold Ctrl-C up.
fn serve(listener: &TcpListener, shared: &Arc<Shared>, stop: &AtomicBool) {
    // Polled, so Ctrl-C is noticed within a few hundredths of a second.
    if listener.set_nonblocking(true).is_err() {
        return;
    }
    let open = Arc::new(AtomicUsize::new(0));
    let waiting = Arc::new(Waiting::default());
    let mut next = 0;
    while !stop.load(Ordering::SeqCst) {
        match listener.accept() {
            Ok((stream, _)) => {
                // Beyond the connections a browser opens at once, the one
                // that has waited longest for its request's head is closed
                // to make room (a local program holding connections idle
                // cannot lock the page out), or, when every one is being
                // answered, the new one: the server never holds more.
                if open.load(Ordering::SeqCst) >= MAX_CONNECTIONS && !waiting.close_oldest() {
                    drop(stream);
                    continue;
                }
                let counted = Counted::new(&open);
                let (shared, waiting) = (Arc::clone(shared), Arc::clone(&waiting));
                let id = next;
                next += 1;
                waiting.enter(id, &stream, &counted);
                std::thread::spawn(move || {
                    let _ending = Ending { waiting: &waiting, id, counted };
                    handle(stream, &shared, &|| waiting.leave(id));
                });
            }
            Err(_) => std::thread::sleep(Duration::from_millis(20)),
        }
    }
    drop(shared.saving.lock().unwrap_or_else(|poisoned| poisoned.into_inner()));
}

/// Connections handled at once at most (a browser opens six to a host).
const MAX_CONNECTIONS: usize = 32;

/// The connections not yet admitted (their request's head still coming,
/// or refused and answered), oldest first: each with a handle to close it
/// by and its count, released as it is closed.
#[derive(Default)]
struct Waiting(Mutex<std::collections::VecDeque<(u64, TcpStream, Counted)>>);

impl Waiting {
    fn list(&self) -> std::sync::MutexGuard<'_, std::collections::VecDeque<(u64, TcpStream, Counted)>> {
        self.0.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Connection `id`, counted by `counted`, waits to be admitted.
    fn enter(&self, id: u64, stream: &TcpStream, counted: &Counted) {
        if let Ok(handle) = stream.try_clone() {
            self.list().push_back((id, handle, counted.clone()));
        }
    }

    /// Connection `id` is admitted (or ended).
    fn leave(&self, id: u64) {
        self.list().retain(|(waiting, ..)| *waiting != id);
    }

    /// Closes the connection that has waited longest, if one waits (its
    /// handler's reads and writes end at once), and counts it out now: the
    /// one accepted in its place does not make the server hold more.
    fn close_oldest(&self) -> bool {
        let oldest = self.list().pop_front();
        oldest.is_some_and(|(_, stream, counted)| {
            let _ = stream.shutdown(std::net::Shutdown::Both);
            counted.release();
            true
        })
    }
}

/// A connection's handler ending, however it ends (a panic too): the
/// connection leaves the waiting list and the server's count.
struct Ending<'a> {
    waiting: &'a Waiting,
    id: u64,
    counted: Counted,
}

impl Drop for Ending<'_> {
    fn drop(&mut self) {
        self.waiting.leave(self.id);
        self.counted.release();
    }
}

/// One open connection in the server's count: counted out once, when it
/// is closed to make room or when its handler ends, whichever comes first.
#[derive(Clone)]
struct Counted {
    open: Arc<AtomicUsize>,
    released: Arc<AtomicBool>,
}

impl Counted {
    fn new(open: &Arc<AtomicUsize>) -> Counted {
        open.fetch_add(1, Ordering::SeqCst);
        Counted { open: Arc::clone(open), released: Arc::new(AtomicBool::new(false)) }
    }

    fn release(&self) {
        if !self.released.swap(true, Ordering::SeqCst) {
            self.open.fetch_sub(1, Ordering::SeqCst);
        }
    }
}

/// Answers one connection's request: its head read and checked first
/// ([`admit`]), its body read only for a request admitted, so that nobody
/// without the token makes the server hold more than a head; `admitted`
/// then (until that, the connection may be closed to make room for
/// another, a refused one too, while its answer goes out).
fn handle(stream: TcpStream, shared: &Shared, admitted: &dyn Fn()) {
    let _ = stream.set_nonblocking(false);
    let _ = stream.set_read_timeout(Some(Duration::from_secs(10)));
    let mut reader = BufReader::new(&stream);
    let (response, head_only) = match http::read_head(&mut reader) {
        Err(status) => (unreadable(status), false),
        Ok(mut request) => {
            let response = match admit(&request, shared) {
                Err(refusal) => refusal,
                Ok(route) => {
                    admitted();
                    match http::read_body(&mut reader, &mut request, MAX_SCENE_BYTES) {
                        Ok(()) => respond(&request, &route, shared),
                        Err(status) => unreadable(status),
                    }
                }
            };
            (response, request.method == "HEAD")
        }
    };
    let _ = response.write_to(&mut &stream, head_only);
    // A body left unread (a request refused before it was read) would make
    // the close a reset, which may cut the answer short at the client:
    // what is still coming is read and dropped, a little at most.
    let _ = stream.shutdown(std::net::Shutdown::Write);
    let _ = stream.set_read_timeout(Some(Duration::from_secs(1)));
    let _ = std::io::copy(&mut reader.take(DRAINED_BYTES), &mut std::io::sink());
}

/// The most of an unread body dropped before a connection is closed.
const DRAINED_BYTES: u64 = 1 << 20;

/// The answer to a request that could not be read, saying why.
fn unreadable(status: u16) -> Response {
    let why = match status {
        413 => format!("the request is too large: a scene may take {} MiB", MAX_SCENE_BYTES >> 20),
        431 => "the request's head is too large".into(),
        411 => "a request's body is sent with Content-Length".into(),
        505 => "this server speaks HTTP/1.1".into(),
        _ => "bad request".into(),
    };
    Response::text(status, &why)
}

/// Where an admitted request goes: its path without the token (the page
/// and its assets are under `/TOKEN/`), and whether the token was there.
struct Route {
    in_path: bool,
    path: String,
}

/// The security checks, on a request's head alone: its route, or the
/// refusal.
fn admit(request: &Request, shared: &Shared) -> Result<Route, Response> {
    if !request.header("host").is_some_and(|host| shared.hosts.iter().any(|h| h.eq_ignore_ascii_case(host))) {
        return Err(Response::text(421, "this server answers only to its own loopback address"));
    }
    if let Some(site) = another_site(request, shared) {
        // Said, so that the user learns a page tried (its text escaped: it
        // is another site's).
        eprintln!(
            "host-sim studio: refused {} {} from another site ({}): only the studio's own page may ask",
            shown(&request.method),
            shown(&request.path),
            shown(&site)
        );
        return Err(Response::text(403, "this server answers only its own page"));
    }
    // The page and its assets, which the browser loads by address, are
    // under /TOKEN/; every other request names the token itself.
    let (in_path, path) = match request.path.strip_prefix('/').and_then(|path| path.split_once('/')) {
        Some((first, _)) if http::same_secret(first, &shared.token) => (true, &request.path[first.len() + 1..]),
        _ => (false, request.path.as_str()),
    };
    // One copy of the token at most, in the query or the header: the copy
    // checked could differ from another one read.
    let mut copies = request.queries("token").chain(request.header("x-studio-token"));
    let named = copies.next();
    if copies.next().is_some() {
        return Err(Response::text(400, "the token is given more than once: give it once"));
    }
    let token_given = named.is_some_and(|t| http::same_secret(t, &shared.token));
    if !(token_given || (in_path && matches!(request.method.as_str(), "GET" | "HEAD"))) {
        return Err(Response::text(403, "a token is needed: open the address host-sim studio printed"));
    }
    Ok(Route { in_path, path: path.to_string() })
}

/// The response to an admitted request.
fn respond(request: &Request, route: &Route, shared: &Shared) -> Response {
    match (request.method.as_str(), route.path.as_str()) {
        // The printed address: the page, under its token (the browser
        // has it now: the file that led it there goes).
        ("GET" | "HEAD", "/") if !route.in_path => {
            shared.forget_launcher();
            let mut response = Response::text(303, "the studio's page");
            response.headers.push(("Location".into(), format!("/{}/", shared.token)));
            response
        }
        ("GET", "/scene") => get_scene(shared),
        ("PUT", "/scene") => put_scene(request, shared),
        // Asked by the page as it opens: no board is an answer, not an
        // error (a 404 the browser's console would report).
        ("GET", "/board") if shared.board.is_none() => {
            Response::new(200, "application/json", b"{\"port\":null}".to_vec())
        }
        ("GET", "/board") => with_board(shared, BoardSender::status),
        ("POST", "/board") => with_board(shared, |board| board.send(&scene_name(shared), &request.body)),
        ("GET" | "HEAD", "/keywords.js") => {
            Response::new(200, "text/javascript; charset=utf-8", keywords_module().into_bytes())
        }
        ("GET" | "HEAD", route) => match ASSETS.iter().find(|(name, _, _)| *name == route) {
            Some((_, kind, body)) => Response::new(200, kind, body.to_vec()),
            None => Response::text(404, "no such page"),
        },
        _ => Response::text(405, "method not allowed"),
    }
}

/// The page's `keywords.js`: the scene format's statement keywords and how
/// many arguments follow each, from the core's one list
/// (`parse::statement_arities`), so that the page's editor highlights and
/// its model finds exactly the statements the core reads.
fn keywords_module() -> String {
    let entries: Vec<String> =
        octrace_core::parse::statement_arities().map(|(keyword, arity)| format!("{keyword}: {arity}")).collect();
    format!(
        "// The scene format's statement keywords, each with how many arguments follow it\n\
         // (for BSPLINE, those before its control points; for FRAMES and MOVE, the fewest):\n\
         // octrace-core's list (parse::statement_arities), as host-sim serves it.\n\
         export const ARITY = Object.freeze({{ {} }});\n",
        entries.join(", ")
    )
}

/// The other site a browser sent `request` for, if it did: an `Origin`
/// that is not this server's, or a `Sec-Fetch-Site` other than
/// `same-origin` and `none` (an address typed or opened by the user).
/// Ports do not separate sites, so another program's page on 127.0.0.1 is
/// `same-site`: refused too. A request without these headers is no
/// browser's, and stands on its token alone.
fn another_site(request: &Request, shared: &Shared) -> Option<String> {
    if let Some(origin) = request.header("origin") {
        let ours = shared.hosts.iter().any(|host| origin.eq_ignore_ascii_case(&format!("http://{host}")));
        if !ours {
            return Some(format!("Origin {origin}"));
        }
    }
    match request.header("sec-fetch-site") {
        None | Some("same-origin" | "none") => None,
        Some(site) => Some(format!("Sec-Fetch-Site {site}")),
    }
}

/// `answer` of the board `--board` names, or 404 without one.
fn with_board(shared: &Shared, answer: impl FnOnce(&BoardSender) -> Response) -> Response {
    match &shared.board {
        Some(board) => answer(board),
        None => Response::text(404, "the studio was started without --board PORT: no board to send to"),
    }
}

/// The version of a scene's text the page loaded, to detect a file changed
/// on disk since (FNV-1a of its bytes; "absent" for no file).
fn version(bytes: Option<&[u8]>) -> String {
    match bytes {
        None => "absent".into(),
        Some(bytes) => {
            let hash =
                bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3));
            format!("{hash:016x}")
        }
    }
}

fn read_scene(path: &Path) -> std::io::Result<Option<Vec<u8>>> {
    match crate::scene::read_scene_file(path) {
        Ok(bytes) => Ok(Some(bytes)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(e),
    }
}

/// The scene's name in messages: its file, or the example's.
fn scene_name(shared: &Shared) -> String {
    shared.scene.as_ref().map_or_else(|| "example.txt".to_string(), |path| ShownPath(path).to_string())
}

fn get_scene(shared: &Shared) -> Response {
    let name = scene_name(shared);
    let (bytes, writable) = match &shared.scene {
        None => (Some(EXAMPLE_SCENE.as_bytes().to_vec()), false),
        Some(path) => match read_scene(path) {
            Ok(bytes) => (bytes, true),
            Err(e) => return Response::text(500, &format!("cannot read {}: {e}", ShownPath(path))),
        },
    };
    let mut response = Response::new(200, "text/plain; charset=utf-8", bytes.clone().unwrap_or_default());
    response.headers.push(("ETag".into(), format!("\"{}\"", version(bytes.as_deref()))));
    response.headers.push(("X-Scene-Name".into(), name.escape_default().to_string()));
    response.headers.push(("X-Scene-Writable".into(), writable.to_string()));
    response
}

/// Saves the scene atomically, unless the file changed since the version
/// in `If-Match` (`*` overwrites whatever is there: the user said so).
fn put_scene(request: &Request, shared: &Shared) -> Response {
    let Some(path) = &shared.scene else {
        return Response::text(403, "the studio was started without a scene file: nothing to save to");
    };
    let Some(expected) = request.header("if-match").map(|v| v.trim().trim_matches('"').to_string()) else {
        return Response::text(428, "If-Match is needed");
    };
    let _guard = shared.saving.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let current = match read_scene(path) {
        Ok(bytes) => version(bytes.as_deref()),
        Err(e) => return Response::text(500, &format!("cannot read {}: {e}", ShownPath(path))),
    };
    if expected != "*" && expected != current {
        let mut response = Response::text(409, "the scene file changed on disk since it was loaded");
        response.headers.push(("ETag".into(), format!("\"{current}\"")));
        return response;
    }
    match write_atomically(path, |f| f.write_all(&request.body)) {
        Ok(()) => {
            let mut response = Response::text(200, "saved");
            response.headers.push(("ETag".into(), format!("\"{}\"", version(Some(&request.body)))));
            response
        }
        Err(e) => Response::text(500, &format!("cannot write {}: {e}", ShownPath(path))),
    }
}

/// 128 random bits in hex, from the operating system.
fn new_token() -> std::io::Result<String> {
    use std::io::Read;
    let mut bytes = [0u8; 16];
    std::fs::File::open("/dev/urandom")?.read_exact(&mut bytes)?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

/// Opens `url` in the desktop's browser without putting its token on a
/// command line (which every user of the machine may read): the browser is
/// given a page that only this user may read, which sends it on. Returns
/// that page's path, to remove once the browser has come.
fn open_browser(url: &str, stderr: &mut dyn Write) -> Option<PathBuf> {
    let opener = if cfg!(target_os = "macos") {
        "open"
    } else if cfg!(windows) {
        "explorer"
    } else {
        "xdg-open"
    };
    let page = format!(
        "<!doctype html><meta charset=\"utf-8\"><meta http-equiv=\"refresh\" content=\"0; url={url}\">\
         <title>octrace studio</title><a href=\"{url}\">octrace studio</a>\n"
    );
    let launcher = match private_page(page.as_bytes()) {
        Ok(path) => path,
        Err(e) => {
            let _ = writeln!(
                stderr,
                "host-sim studio: cannot write the page for the browser: {e}; open the address above yourself"
            );
            return None;
        }
    };
    match std::process::Command::new(opener).arg(&launcher).spawn() {
        Err(e) => {
            let _ = writeln!(stderr, "host-sim studio: cannot run {opener}: {e}; open the address above yourself");
            let _ = std::fs::remove_file(&launcher);
            return None;
        }
        // An opener that finds no browser says so in its own words and
        // exits: said here too, while the server goes on.
        Ok(mut child) => {
            std::thread::spawn(move || {
                if let Ok(status) = child.wait() {
                    if !status.success() {
                        eprintln!(
                            "host-sim studio: {opener} opened no browser ({status}); open the address above yourself"
                        );
                    }
                }
            });
        }
    }
    Some(launcher)
}

/// A new page in the system's temporary directory holding `contents`,
/// readable by this user alone from its making.
fn private_page(contents: &[u8]) -> std::io::Result<PathBuf> {
    let mut options = std::fs::File::options();
    options.write(true).create_new(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::mode(&mut options, 0o600);
    let dir = std::env::temp_dir();
    let (path, mut file) = crate::output::create_unguessable(&options, || {
        dir.join(format!("host-sim-studio-{}-{}.html", std::process::id(), crate::output::random_hex()))
    })?;
    let written = file.write_all(contents).and_then(|()| file.sync_all());
    if let Err(e) = written {
        let _ = std::fs::remove_file(&path);
        return Err(e);
    }
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn versions_follow_the_content() {
        assert_eq!(version(None), "absent");
        assert_eq!(version(Some(b"a")), version(Some(b"a")));
        assert_ne!(version(Some(b"a")), version(Some(b"b")));
    }

    #[test]
    fn tokens_are_long_and_differ() {
        let (a, b) = (new_token().unwrap(), new_token().unwrap());
        assert_eq!(a.len(), 32);
        assert_ne!(a, b);
    }
}
