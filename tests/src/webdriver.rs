//! Just enough of a W3C WebDriver client, over std's TCP, to drive Debian's
//! chromium through chromedriver in the studio tests: sessions, navigation,
//! scripts, pointer actions, elements, alerts and screenshots.

use serde_json::{json, Value};
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// How many chromedrivers [`Browser::start`] starts before it gives up.
const STARTS: usize = 3;

/// A chromedriver process and one headless chromium session, both ended on
/// drop.
pub struct Browser {
    driver: Child,
    port: u16,
    session: String,
    _profile: tempfile::TempDir,
}

/// A free port on 127.0.0.1 (bound and released: racy only in theory).
pub fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0").and_then(|l| l.local_addr()).map(|a| a.port()).expect("a free port")
}

/// One HTTP/1.1 request to 127.0.0.1:`port`; returns (status, body).
pub fn http(port: u16, method: &str, path: &str, headers: &[(&str, &str)], body: &[u8]) -> (u16, Vec<u8>) {
    let (status, _, body) = http_with_head(port, method, path, headers, body);
    (status, body)
}

/// As [`http`], with the response's head (its status line and headers) too.
pub fn http_with_head(
    port: u16,
    method: &str,
    path: &str,
    headers: &[(&str, &str)],
    body: &[u8],
) -> (u16, String, Vec<u8>) {
    try_http_with_head(port, method, path, headers, body)
        .unwrap_or_else(|e| panic!("{method} {path} on 127.0.0.1:{port}: {e}"))
}

/// [`http_with_head`], its failures to connect, send or read returned.
fn try_http_with_head(
    port: u16,
    method: &str,
    path: &str,
    headers: &[(&str, &str)],
    body: &[u8],
) -> std::io::Result<(u16, String, Vec<u8>)> {
    let closed = |what: &str| std::io::Error::new(std::io::ErrorKind::UnexpectedEof, what.to_string());
    let mut stream = TcpStream::connect(("127.0.0.1", port))?;
    stream.set_read_timeout(Some(crate::HANG_GUARD)).ok();
    let mut head = format!("{method} {path} HTTP/1.1\r\nContent-Length: {}\r\nConnection: close\r\n", body.len());
    if !headers.iter().any(|(n, _)| n.eq_ignore_ascii_case("host")) {
        head.push_str(&format!("Host: 127.0.0.1:{port}\r\n"));
    }
    for (n, v) in headers {
        head.push_str(&format!("{n}: {v}\r\n"));
    }
    head.push_str("\r\n");
    stream.write_all(head.as_bytes())?;
    stream.write_all(body)?;
    // chromedriver keeps the connection open whatever the request says: read
    // the head, then Content-Length bytes (or to the end without one).
    let mut response = Vec::new();
    let mut buffer = [0u8; 65536];
    let split = loop {
        if let Some(split) = response.windows(4).position(|w| w == b"\r\n\r\n") {
            break split;
        }
        let n = stream.read(&mut buffer)?;
        if n == 0 {
            return Err(closed("the connection closed before the response's head ended"));
        }
        response.extend_from_slice(&buffer[..n]);
    };
    let head = String::from_utf8_lossy(&response[..split]).into_owned();
    let status = head.split(' ').nth(1).and_then(|s| s.parse().ok()).expect("a status");
    let length = head.lines().find_map(|l| {
        let (name, value) = l.split_once(':')?;
        name.trim().eq_ignore_ascii_case("content-length").then(|| value.trim().parse::<usize>().ok())?
    });
    let mut body = response[split + 4..].to_vec();
    match length {
        Some(length) => {
            while body.len() < length {
                let n = stream.read(&mut buffer)?;
                if n == 0 {
                    return Err(closed("the connection closed inside the body"));
                }
                body.extend_from_slice(&buffer[..n]);
            }
            body.truncate(length);
        }
        None => {
            stream.read_to_end(&mut body)?;
        }
    }
    Ok((status, head, body))
}

impl Browser {
    /// Starts chromedriver and a fresh headless chromium (its own profile).
    ///
    /// A chromedriver that fails to make the session (on a loaded machine
    /// one once reset the connection that asked for it) is ended and a new
    /// one started on another port, up to [`STARTS`] times in all.
    pub fn start(window: (u32, u32)) -> Browser {
        for tool in ["/usr/bin/chromium", "/usr/bin/chromedriver"] {
            assert!(
                Path::new(tool).exists(),
                "{tool} is missing: install Debian's chromium and chromium-driver (scripts/test-all does)"
            );
        }
        let mut failures = Vec::new();
        for _ in 0..STARTS {
            match Browser::try_start(window) {
                Ok(browser) => return browser,
                Err(failure) => failures.push(failure),
            }
        }
        panic!("chromedriver made no session in {STARTS} starts: {}", failures.join("; "))
    }

    /// One chromedriver and its session, or why the session was not made
    /// (the driver is then ended, with the rest, on drop).
    fn try_start(window: (u32, u32)) -> Result<Browser, String> {
        let port = free_port();
        let mut driver = Command::new("/usr/bin/chromedriver");
        driver.arg(format!("--port={port}")).stdout(Stdio::null()).stderr(Stdio::null());
        let driver = crate::children::spawn(&mut driver).expect("chromedriver starts");
        let deadline = Instant::now() + crate::HANG_GUARD;
        while TcpStream::connect(("127.0.0.1", port)).is_err() {
            assert!(Instant::now() < deadline, "chromedriver did not start listening");
            std::thread::sleep(Duration::from_millis(50));
        }
        let profile = tempfile::tempdir().expect("a profile directory");
        let args = vec![
            "--headless".to_string(),
            "--no-sandbox".into(),
            "--disable-gpu".into(),
            "--disable-quic".into(),
            "--no-first-run".into(),
            "--disable-background-networking".into(),
            "--disable-component-update".into(),
            "--disable-sync".into(),
            format!("--user-data-dir={}", profile.path().display()),
            format!("--window-size={},{}", window.0, window.1),
        ];
        let mut browser = Browser { driver, port, session: String::new(), _profile: profile };
        let request = json!({"capabilities": {"alwaysMatch": {"browserName": "chrome",
            "unhandledPromptBehavior": "ignore",
            "goog:chromeOptions": {"binary": "/usr/bin/chromium", "args": args}}}});
        let (status, created) =
            browser.request("POST", "/session", request).map_err(|e| format!("POST /session: {e}"))?;
        match created["value"]["sessionId"].as_str() {
            Some(session) if status == 200 => browser.session = session.to_string(),
            _ => return Err(format!("POST /session: {status} {created}")),
        }
        Ok(browser)
    }

    /// One WebDriver request to the driver: its status and its JSON (null
    /// when the body is none), or the failure to connect, send or read.
    fn request(&self, method: &str, path: &str, body: Value) -> std::io::Result<(u16, Value)> {
        let body = if method == "GET" || method == "DELETE" { Vec::new() } else { body.to_string().into_bytes() };
        let json = [("Content-Type", "application/json; charset=utf-8")];
        let (status, _, response) = try_http_with_head(self.port, method, path, &json, &body)?;
        Ok((status, serde_json::from_slice(&response).unwrap_or(Value::Null)))
    }

    fn command(&self, method: &str, path: &str, body: Value) -> Value {
        let (status, value) =
            self.request(method, path, body).unwrap_or_else(|e| panic!("WebDriver {method} {path}: {e}"));
        assert!(status == 200, "WebDriver {method} {path}: {status} {value}");
        value.get("value").cloned().unwrap_or(value)
    }

    fn session(&self, method: &str, path: &str, body: Value) -> Value {
        self.command(method, &format!("/session/{}{path}", self.session), body)
    }

    /// Tries a command; the error message when it fails.
    fn try_session(&self, method: &str, path: &str, body: Value) -> Result<Value, String> {
        let path = format!("/session/{}{path}", self.session);
        let (status, value) =
            self.request(method, &path, body).unwrap_or_else(|e| panic!("WebDriver {method} {path}: {e}"));
        if status == 200 {
            Ok(value["value"].clone())
        } else {
            Err(value["value"]["message"].as_str().unwrap_or("").to_string())
        }
    }

    pub fn goto(&self, url: &str) {
        self.session("POST", "/url", json!({ "url": url }));
    }

    /// Runs `script` (a function body; a returned promise is awaited).
    pub fn run(&self, script: &str) -> Value {
        self.session("POST", "/execute/sync", json!({ "script": script, "args": [] }))
    }

    /// Waits until `condition` (a JavaScript expression) is true (up to
    /// [`crate::HANG_GUARD`]: a hang).
    pub fn wait_for(&self, condition: &str) {
        let deadline = Instant::now() + crate::HANG_GUARD;
        while self.run(&format!("return !!({condition});")) != Value::Bool(true) {
            assert!(Instant::now() < deadline, "timed out waiting for {condition}");
            std::thread::sleep(Duration::from_millis(25));
        }
    }

    /// The WebDriver reference of the element `css` selects.
    pub fn element(&self, css: &str) -> Value {
        self.session("POST", "/element", json!({"using": "css selector", "value": css}))
    }

    pub fn click(&self, css: &str) {
        let id = element_id(&self.element(css));
        self.session("POST", &format!("/element/{id}/click"), json!({}));
    }

    /// Types `keys` into the element `css` selects.
    pub fn type_into(&self, css: &str, keys: &str) {
        self.type_into_element(&self.element(css), keys);
    }

    /// Types `keys` into `element` (a reference, as [`Browser::element`] or
    /// a script returning an element gives it: one in a shadow root too).
    pub fn type_into_element(&self, element: &Value, keys: &str) {
        let id = element_id(element);
        self.session("POST", &format!("/element/{id}/value"), json!({ "text": keys }));
    }

    /// Presses the mouse at `from` (pixels from the element's centre), drags
    /// through `to` and releases.
    pub fn drag(&self, css: &str, from: (i64, i64), to: (i64, i64)) {
        let element = self.element(css);
        let mv = |(x, y): (i64, i64), duration: u64| json!({"type": "pointerMove", "origin": element.clone(), "x": x, "y": y, "duration": duration});
        let actions = json!({"actions": [{"type": "pointer", "id": "mouse", "parameters": {"pointerType": "mouse"},
            "actions": [mv(from, 0), {"type": "pointerDown", "button": 0},
                        mv(((from.0 + to.0) / 2, (from.1 + to.1) / 2), 50), mv(to, 50),
                        {"type": "pointerUp", "button": 0}]}]});
        self.session("POST", "/actions", actions);
    }

    /// Presses and releases each key of `keys` in turn (WebDriver key
    /// codes: "\u{E009}" holds Control until pressed again).
    pub fn keys(&self, keys: &str) {
        let mut actions = Vec::new();
        let mut held = Vec::new();
        for key in keys.chars() {
            let modifier = matches!(key, '\u{E008}' | '\u{E009}' | '\u{E00A}');
            if modifier && held.contains(&key) {
                actions.push(json!({"type": "keyUp", "value": key.to_string()}));
                held.retain(|&k| k != key);
            } else if modifier {
                actions.push(json!({"type": "keyDown", "value": key.to_string()}));
                held.push(key);
            } else {
                actions.push(json!({"type": "keyDown", "value": key.to_string()}));
                actions.push(json!({"type": "keyUp", "value": key.to_string()}));
            }
        }
        self.session("POST", "/actions", json!({"actions": [{"type": "key", "id": "keyboard", "actions": actions}]}));
    }

    /// The text of an open alert or confirm, if one is open.
    pub fn alert_text(&self) -> Option<String> {
        self.try_session("GET", "/alert/text", Value::Null).ok().and_then(|v| v.as_str().map(str::to_owned))
    }

    pub fn answer_alert(&self, accept: bool) {
        self.session("POST", if accept { "/alert/accept" } else { "/alert/dismiss" }, json!({}));
    }

    /// A PNG of the viewport.
    pub fn screenshot(&self) -> Vec<u8> {
        let encoded = self.session("GET", "/screenshot", Value::Null);
        base64_decode(encoded.as_str().expect("base64"))
    }

    /// The RGB pixels of `<canvas id=…>`, with its size.
    pub fn canvas_rgb(&self, id: &str) -> (u32, u32, Vec<u8>) {
        let v = self.run(&format!(
            "const c = document.getElementById('{id}');
             const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
             let s = '';
             for (let i = 0; i < d.length; i += 4) s += String.fromCharCode(d[i], d[i + 1], d[i + 2]);
             return [c.width, c.height, btoa(s)];"
        ));
        let (w, h) = (v[0].as_u64().expect("width") as u32, v[1].as_u64().expect("height") as u32);
        (w, h, base64_decode(v[2].as_str().expect("pixels")))
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        if !self.session.is_empty() {
            let _ = self.try_session("DELETE", "", Value::Null);
        }
        let _ = self.driver.kill();
        let _ = self.driver.wait();
    }
}

fn element_id(element: &Value) -> String {
    element["element-6066-11e4-a52e-4f735466cecf"]
        .as_str()
        .unwrap_or_else(|| panic!("an element reference: {element}"))
        .to_string()
}

/// Standard base64 (with padding) to bytes.
pub fn base64_decode(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        _ => 63,
    };
    let symbols: Vec<u8> = text.bytes().filter(|&c| c != b'=' && !c.is_ascii_whitespace()).map(value).collect();
    let mut out = Vec::with_capacity(symbols.len() * 3 / 4);
    for chunk in symbols.chunks(4) {
        let bits = chunk.iter().enumerate().fold(0u32, |acc, (i, &v)| acc | (v as u32) << (18 - 6 * i));
        out.extend(&bits.to_be_bytes()[1..chunk.len()]);
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn base64_decodes() {
        assert_eq!(super::base64_decode("aGVsbG8="), b"hello");
        assert_eq!(super::base64_decode("AP8A"), [0, 255, 0]);
    }
}
