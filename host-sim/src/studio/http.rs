//! Just enough HTTP/1.1 for the studio: one request per connection (every
//! response says `Connection: close`), bodies by Content-Length only.
//!
//! Invariant: reading never allocates more than the header limit plus the
//! body limit the caller gives, whatever the peer declares.

use std::io::{BufRead, BufReader, Read, Write};

/// The most the request line and headers may take together.
const MAX_HEAD_BYTES: usize = 16 << 10;

/// A parsed request. Header names are lower-case.
pub(crate) struct Request {
    pub(crate) method: String,
    /// The path without the query, exactly as sent (never decoded: it is
    /// only ever compared with the assets' names).
    pub(crate) path: String,
    query: Vec<(String, String)>,
    headers: Vec<(String, String)>,
    pub(crate) body: Vec<u8>,
}

impl Request {
    pub(crate) fn header(&self, name: &str) -> Option<&str> {
        self.headers.iter().find(|(n, _)| n == name).map(|(_, v)| v.as_str())
    }

    /// Every value of `name` in the query, in order.
    pub(crate) fn queries<'r>(&'r self, name: &'r str) -> impl Iterator<Item = &'r str> + 'r {
        self.query.iter().filter(move |(n, _)| n == name).map(|(_, v)| v.as_str())
    }
}

/// Headers a request may give once at most: the ones the security checks
/// and the body's length are told from (a second copy could say otherwise
/// than the one checked).
const SINGLE_HEADERS: [&str; 6] =
    ["host", "origin", "sec-fetch-site", "x-studio-token", "content-length", "transfer-encoding"];

/// Reads one request's line and headers (its body, if any, is left to
/// [`read_body`], once the request is admitted); on a malformed or
/// oversized one, the status to answer with.
pub(crate) fn read_head(reader: &mut BufReader<impl Read>) -> Result<Request, u16> {
    let mut head = Vec::new();
    loop {
        let before = head.len();
        let read = (&mut *reader)
            .take((MAX_HEAD_BYTES + 1 - before) as u64)
            .read_until(b'\n', &mut head)
            .map_err(|_| 400u16)?;
        if head.len() > MAX_HEAD_BYTES {
            return Err(431);
        }
        if read == 0 {
            return Err(400);
        }
        let line = &head[before..];
        if line == b"\r\n" || line == b"\n" {
            break;
        }
    }
    let head = std::str::from_utf8(&head).map_err(|_| 400u16)?;
    let mut lines = head.lines();
    let mut request_line = lines.next().unwrap_or("").split(' ');
    let (Some(method), Some(target), Some(version)) = (request_line.next(), request_line.next(), request_line.next())
    else {
        return Err(400);
    };
    if !version.starts_with("HTTP/1.") {
        return Err(505);
    }
    let headers: Vec<(String, String)> = lines
        .filter_map(|line| line.split_once(':'))
        .map(|(name, value)| (name.trim().to_ascii_lowercase(), value.trim().to_string()))
        .collect();
    let (path, query) = target.split_once('?').unwrap_or((target, ""));
    let query = query
        .split('&')
        .filter_map(|pair| pair.split_once('='))
        .map(|(n, v)| (percent_decode(n), percent_decode(v)))
        .collect();
    if SINGLE_HEADERS.iter().any(|single| headers.iter().filter(|(name, _)| name == single).count() > 1) {
        return Err(400);
    }
    let request = Request { method: method.to_string(), path: path.to_string(), query, headers, body: Vec::new() };
    if request.header("transfer-encoding").is_some() {
        return Err(411);
    }
    Ok(request)
}

/// Reads `request`'s body (by its Content-Length, at most `max_body`
/// bytes) from `reader`, which read its head; on a malformed or oversized
/// one, the status to answer with.
pub(crate) fn read_body(reader: &mut BufReader<impl Read>, request: &mut Request, max_body: usize) -> Result<(), u16> {
    let length = match request.header("content-length") {
        None => 0,
        Some(v) => v.parse::<usize>().map_err(|_| 400u16)?,
    };
    if length > max_body {
        return Err(413);
    }
    let mut body = vec![0; length];
    reader.read_exact(&mut body).map_err(|_| 400u16)?;
    request.body = body;
    Ok(())
}

/// A status's reason phrase.
fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        303 => "See Other",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        409 => "Conflict",
        411 => "Length Required",
        413 => "Content Too Large",
        422 => "Unprocessable Content",
        421 => "Misdirected Request",
        428 => "Precondition Required",
        431 => "Request Header Fields Too Large",
        502 => "Bad Gateway",
        505 => "HTTP Version Not Supported",
        _ => "Error",
    }
}

fn percent_decode(text: &str) -> String {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        match (bytes[i], bytes.get(i + 1).copied().and_then(hex), bytes.get(i + 2).copied().and_then(hex)) {
            (b'%', Some(high), Some(low)) => {
                out.push((high * 16 + low) as u8);
                i += 3;
            }
            (b'+', _, _) => {
                out.push(b' ');
                i += 1;
            }
            (b, _, _) => {
                out.push(b);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Compares a secret in time that does not depend on where they differ.
pub(crate) fn same_secret(given: &str, secret: &str) -> bool {
    given.len() == secret.len() && given.bytes().zip(secret.bytes()).fold(0u8, |acc, (a, b)| acc | (a ^ b)) == 0
}

/// What the page may load and run: its own server's scripts, styles and
/// module (compiled from there), nothing framed, no form sent anywhere.
const CONTENT_SECURITY_POLICY: &str = "default-src 'self'; script-src 'self' 'wasm-unsafe-eval'; \
     style-src 'self'; img-src 'self' data: blob:; frame-ancestors 'none'; base-uri 'none'; form-action 'none'";

pub(crate) struct Response {
    status: u16,
    pub(crate) headers: Vec<(String, String)>,
    body: Vec<u8>,
}

impl Response {
    pub(crate) fn new(status: u16, content_type: &str, body: Vec<u8>) -> Response {
        Response { status, headers: vec![("Content-Type".into(), content_type.into())], body }
    }

    pub(crate) fn text(status: u16, message: &str) -> Response {
        Response::new(status, "text/plain; charset=utf-8", format!("{message}\n").into_bytes())
    }

    /// Writes the response; `head_only` (a HEAD request): its head alone,
    /// the body's length still given.
    pub(crate) fn write_to(&self, out: &mut impl Write, head_only: bool) -> std::io::Result<()> {
        let mut head = format!("HTTP/1.1 {} {}\r\n", self.status, reason(self.status));
        for (name, value) in &self.headers {
            head.push_str(&format!("{name}: {value}\r\n"));
        }
        // The page is the only client: no caching of a scene or a module
        // that may have changed; no framing by, embedding in or handle to
        // other sites' pages; no address (with its token) in a Referer;
        // scripts and the module from this server alone.
        head.push_str(&format!(
            "Content-Length: {}\r\nCache-Control: no-store\r\nX-Frame-Options: DENY\r\n\
             X-Content-Type-Options: nosniff\r\nReferrer-Policy: no-referrer\r\n\
             Cross-Origin-Resource-Policy: same-origin\r\nCross-Origin-Opener-Policy: same-origin\r\n\
             Content-Security-Policy: {CONTENT_SECURITY_POLICY}\r\nConnection: close\r\n\r\n",
            self.body.len()
        ));
        out.write_all(head.as_bytes())?;
        if !head_only {
            out.write_all(&self.body)?;
        }
        out.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A request's head, then its body, as the studio reads them.
    fn read_request(mut raw: &[u8], max_body: usize) -> Result<Request, u16> {
        let mut reader = BufReader::new(&mut raw);
        let mut request = read_head(&mut reader)?;
        read_body(&mut reader, &mut request, max_body)?;
        Ok(request)
    }

    #[test]
    fn requests_are_parsed() {
        let raw = b"PUT /scene?token=a%62c HTTP/1.1\r\nHost: 127.0.0.1:9\r\nContent-Length: 3\r\n\r\nabcdef";
        let request = read_request(&raw[..], 10).unwrap();
        assert_eq!((request.method.as_str(), request.path.as_str()), ("PUT", "/scene"));
        assert_eq!(request.queries("token").collect::<Vec<_>>(), ["abc"]);
        assert_eq!(request.header("host"), Some("127.0.0.1:9"));
        assert_eq!(request.body, b"abc");
    }

    #[test]
    fn oversized_or_malformed_requests_are_refused() {
        let big = b"PUT / HTTP/1.1\r\nContent-Length: 11\r\n\r\n";
        assert_eq!(read_request(&big[..], 10).err(), Some(413));
        let long_head = format!("GET / HTTP/1.1\r\nX: {}\r\n\r\n", "a".repeat(MAX_HEAD_BYTES));
        assert_eq!(read_request(long_head.as_bytes(), 10).err(), Some(431));
        assert_eq!(read_request(&b"GET /\r\n\r\n"[..], 10).err(), Some(400));
        assert_eq!(read_request(&b""[..], 10).err(), Some(400));
        // A second Host (or token, or length) could say otherwise than the
        // one checked: refused.
        let twice = b"GET / HTTP/1.1\r\nHost: 127.0.0.1:9\r\nhost: evil.com\r\n\r\n";
        assert_eq!(read_request(&twice[..], 10).err(), Some(400));
    }

    #[test]
    fn a_head_answer_has_no_body() {
        let response = Response::text(200, "hello");
        let (mut whole, mut head) = (Vec::new(), Vec::new());
        response.write_to(&mut whole, false).unwrap();
        response.write_to(&mut head, true).unwrap();
        assert!(whole.ends_with(b"\r\n\r\nhello\n") && head.ends_with(b"\r\n\r\n"));
        assert!(String::from_utf8(head).unwrap().contains("Content-Length: 6\r\n"));
    }

    #[test]
    fn secrets_compare_whole() {
        assert!(same_secret("abc", "abc"));
        assert!(!same_secret("abd", "abc"));
        assert!(!same_secret("ab", "abc"));
    }
}
