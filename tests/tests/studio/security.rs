//! The studio's server: its token, its origin and host checks, the port and the
//! scene it starts with, and another local page that tries to drive it.

use super::*;

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

/// A program without the token holding connections open (twice the 32
/// the server handles at once, sending nothing) cannot keep the page out.
#[test]
fn idle_connections_cannot_lock_the_page_out() {
    let dir = tempfile::tempdir().expect("a directory");
    let scene_path = dir.path().join("s.txt");
    std::fs::write(&scene_path, START).expect("written");
    let studio = Studio::start(Some(&scene_path));
    // Twice the connections the server handles at once, none sending a
    // byte: each beyond them closes the one that has waited longest.
    let idle: Vec<_> =
        (0..64).map(|_| std::net::TcpStream::connect(("127.0.0.1", studio.port)).expect("connects")).collect();
    let (status, scene) = http(studio.port, "GET", "/scene", &[("X-Studio-Token", &studio.token)], b"");
    assert_eq!((status, scene.as_slice()), (200, START.as_bytes()));
    drop(idle);
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
