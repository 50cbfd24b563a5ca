//! A local HTTP server for the tests that fetch tilesets (`splatgl::files::http`).

use std::io::{BufRead, BufReader, Write};
use std::net::TcpListener;
use std::path::Path;
use std::sync::{Arc, Mutex};

/// Serves `root` over HTTP/1.1 on a free local port until the test ends (GET only, one
/// request per connection); returns the base URL and the log of paths requested. Paths are
/// read as real servers read them: percent-decoded, then `.` and `..` resolved (a `..` above
/// the root is a 400), so a client that sends `%2e%2e/x` gets `../x`; the log holds the paths
/// as the server resolved them.
pub fn serve(root: &Path) -> (String, Arc<Mutex<Vec<String>>>) {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let base = format!("http://{}", listener.local_addr().unwrap());
    let log = Arc::new(Mutex::new(Vec::new()));
    let (root, seen) = (root.to_owned(), log.clone());
    std::thread::spawn(move || {
        for stream in listener.incoming().flatten() {
            let mut r = BufReader::new(&stream);
            let mut line = String::new();
            if r.read_line(&mut line).is_err() {
                continue;
            }
            // Skip the headers.
            let mut h = String::new();
            while r.read_line(&mut h).is_ok_and(|n| n > 2) {
                h.clear();
            }
            let raw = line.split_whitespace().nth(1).unwrap_or("/");
            let path = server_path(raw);
            seen.lock()
                .unwrap()
                .push(path.clone().unwrap_or_else(|| format!("<refused {raw}>")));
            let file = path.map(|p| root.join(p.trim_start_matches('/')));
            let mut w = &stream;
            let _ = match file.and_then(|f| std::fs::read(f).ok()) {
                Some(body) => w
                    .write_all(
                        format!(
                            "HTTP/1.1 200 OK\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
                            body.len()
                        )
                        .as_bytes(),
                    )
                    .and_then(|_| w.write_all(&body)),
                None => w.write_all(
                    b"HTTP/1.1 404 Not Found\r\nContent-Length: 0\r\nConnection: close\r\n\r\n",
                ),
            };
        }
    });
    (base, log)
}

/// `raw` (a request target) as a server resolves it: query dropped, percent-decoded,
/// `.`/`..` removed; `None` when a `..` climbs above the root.
fn server_path(raw: &str) -> Option<String> {
    let raw = raw.split(['?', '#']).next().unwrap_or("/");
    let mut bytes = Vec::new();
    let b = raw.as_bytes();
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        match (
            b[i],
            b.get(i + 1).and_then(|c| hex(*c)),
            b.get(i + 2).and_then(|c| hex(*c)),
        ) {
            (b'%', Some(h), Some(l)) => {
                bytes.push((h * 16 + l) as u8);
                i += 3;
            }
            (c, _, _) => {
                bytes.push(c);
                i += 1;
            }
        }
    }
    let decoded = String::from_utf8_lossy(&bytes).into_owned();
    let mut out: Vec<&str> = Vec::new();
    for seg in decoded.split('/') {
        match seg {
            "" | "." => {}
            ".." => {
                out.pop()?;
            }
            s => out.push(s),
        }
    }
    Some(format!("/{}", out.join("/")))
}
