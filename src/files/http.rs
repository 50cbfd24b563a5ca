//! Files named by `http://` and `https://` URLs (tilesets and their tiles): fetched whole
//! within a byte limit, and resolved against their document's URL under the same containment
//! rule as files on disk — a relative or absolute URI must stay under the folder of the
//! document's URL (same scheme, host and port, path below it) unless `allow_outside`.
//!
//! Redirects are not followed (one could leave the folder); a response other than 200 is an
//! error naming its status. Timeouts: 10 s to connect, 120 s in all. Without the `http`
//! feature every fetch is an error saying so.

use std::io;

/// Whether `s` is an `http://` or `https://` URL.
pub fn is_url(s: &str) -> bool {
    let l = s.get(..8).unwrap_or(s).to_ascii_lowercase();
    l.starts_with("http://") || l.starts_with("https://")
}

/// `scheme://host[:port]` and the path (from its `/`, without query or fragment) of `url`.
fn split(url: &str) -> Option<(&str, &str)> {
    let after = url.find("://")? + 3;
    let path_at = url[after..].find('/').map_or(url.len(), |i| after + i);
    let end = url.find(['?', '#']).unwrap_or(url.len()).max(path_at);
    Some((&url[..path_at], &url[path_at..end]))
}

/// Percent-decodes each segment of `path` (as the server will), removes `.` and `..`
/// segments, and percent-encodes the result again, so the request names exactly the path that
/// was checked. `Err` names why: an encoded separator (`%2F`, `%5C`), a backslash or a NUL
/// (servers read them differently) or a `..` that climbs above the root.
fn normalize(path: &str) -> Result<String, &'static str> {
    let mut out: Vec<String> = Vec::new();
    for seg in path.split('/').skip(1) {
        let decoded = super::percent_decode(seg);
        if decoded.contains(['/', '\\', '\0']) {
            return Err("has an encoded separator, a backslash or a NUL in a segment");
        }
        match decoded.as_str() {
            "." => {}
            ".." => {
                out.pop().ok_or("climbs above the host's root")?;
            }
            _ => out.push(encode_segment(&decoded)),
        }
    }
    Ok(format!("/{}", out.join("/")))
}

/// `seg` percent-encoded but for RFC 3986's unreserved characters and the sub-delimiters
/// servers take literally.
fn encode_segment(seg: &str) -> String {
    let mut out = String::with_capacity(seg.len());
    for b in seg.bytes() {
        if b.is_ascii_alphanumeric() || b"-._~!$&'()*+,;=:@".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

/// `uri` resolved against the document at `base`, kept under `base`'s folder unless
/// `allow_outside`. Errors name the rule. Percent-encoding is decoded before the check, as a
/// server decodes it (`%2e%2e/x` is `../x`), and the URL returned names the checked path.
pub fn resolve(base: &str, uri: &str, allow_outside: bool) -> io::Result<String> {
    let bad = |m: String| io::Error::new(io::ErrorKind::PermissionDenied, m);
    let refused = |why: &str| bad(format!("{uri:?} {why}"));
    let (origin, path) =
        split(base).ok_or_else(|| bad(format!("{base:?} is not an http(s) URL")))?;
    // The base's folder as the server reads it (decoded, normalised, encoded again).
    let path = normalize(path).map_err(|why| bad(format!("{base:?} {why}")))?;
    let folder = &path[..path.rfind('/').map_or(0, |i| i + 1)];
    let uri_path = uri.find(['?', '#']).map_or(uri, |i| &uri[..i]);
    let (o, p) = if is_url(uri) {
        split(uri).ok_or_else(|| bad(format!("{uri:?} is not a URL")))?
    } else if uri_path.starts_with('/') {
        (origin, uri_path)
    } else {
        let p = normalize(&format!("{folder}{uri_path}")).map_err(refused)?;
        return check(origin, folder, &p, allow_outside, uri);
    };
    let p = normalize(p).map_err(refused)?;
    if !o.eq_ignore_ascii_case(origin) && !allow_outside {
        return Err(bad(format!(
            "{uri:?} is on another host than the tileset ({origin}); --allow-outside-paths allows it"
        )));
    }
    check(o, folder, &p, allow_outside, uri)
}

fn check(
    origin: &str,
    folder: &str,
    path: &str,
    allow_outside: bool,
    uri: &str,
) -> io::Result<String> {
    if !allow_outside && !path.starts_with(folder) {
        return Err(io::Error::new(
            io::ErrorKind::PermissionDenied,
            format!(
                "{uri:?} resolves outside the asset's folder ({origin}{folder}); \
                 --allow-outside-paths allows it"
            ),
        ));
    }
    Ok(format!("{origin}{path}"))
}

/// Fetches `url` whole, at most `limit` bytes; `what` names it in errors.
#[cfg(feature = "http")]
pub fn fetch_bounded(url: &str, limit: u64, what: &str) -> io::Result<Vec<u8>> {
    use std::time::Duration;
    let config = ureq::Agent::config_builder();
    // macOS: the system's TLS (the only provider built there, see Cargo.toml).
    #[cfg(target_os = "macos")]
    let config = config.tls_config(
        ureq::tls::TlsConfig::builder()
            .provider(ureq::tls::TlsProvider::NativeTls)
            .build(),
    );
    let agent: ureq::Agent = config
        .max_redirects(0)
        .http_status_as_error(false)
        .timeout_connect(Some(Duration::from_secs(10)))
        .timeout_global(Some(Duration::from_secs(120)))
        .build()
        .into();
    let other = |e: ureq::Error| io::Error::other(format!("{what}: {url}: {e}"));
    let mut r = agent.get(url).call().map_err(other)?;
    let status = r.status();
    if status != 200 {
        return Err(io::Error::new(
            if status == 404 {
                io::ErrorKind::NotFound
            } else {
                io::ErrorKind::Other
            },
            format!("{what}: {url}: HTTP {status}"),
        ));
    }
    r.body_mut()
        .with_config()
        .limit(limit)
        .read_to_vec()
        .map_err(|e| match e {
            ureq::Error::BodyExceedsLimit(_) => io::Error::new(
                io::ErrorKind::InvalidData,
                format!("{what}: {url}: larger than the limit of {limit} bytes (--max-bytes)"),
            ),
            e => other(e),
        })
}

/// Without the `http` feature: an error saying so.
#[cfg(not(feature = "http"))]
pub fn fetch_bounded(url: &str, _limit: u64, what: &str) -> io::Result<Vec<u8>> {
    Err(io::Error::new(
        io::ErrorKind::Unsupported,
        format!("{what}: {url}: splatgl was built without the `http` feature"),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uris_resolve_under_the_tileset_folder_and_nowhere_else() {
        let base = "http://h:8/a/b/tileset.json?k=1";
        assert_eq!(
            resolve(base, "t/r0.glb", false).unwrap(),
            "http://h:8/a/b/t/r0.glb"
        );
        assert_eq!(
            resolve(base, "./t/../r.glb", false).unwrap(),
            "http://h:8/a/b/r.glb"
        );
        assert_eq!(
            resolve(base, "/a/b/x.glb", false).unwrap(),
            "http://h:8/a/b/x.glb"
        );
        assert_eq!(
            resolve(base, "http://h:8/a/b/y.glb", false).unwrap(),
            "http://h:8/a/b/y.glb"
        );
        for escape in [
            "../x.glb",
            "/a/x.glb",
            "http://other/a/b/x.glb",
            "../../../../x",
        ] {
            assert!(resolve(base, escape, false).is_err(), "{escape}");
        }
        assert_eq!(
            resolve(base, "../x.glb", true).unwrap(),
            "http://h:8/a/x.glb"
        );
        assert!(is_url("HTTPS://x/y") && !is_url("tiles/x.glb"));
    }

    #[test]
    fn percent_encoded_dots_and_separators_cannot_leave_the_folder() {
        let base = "http://h:8/a/b/tileset.json";
        for escape in [
            "%2e%2e/secret.glb",
            "%2E%2E/secret.glb",
            "..%2fsecret.glb",
            "%2e%2e%2fsecret.glb",
            "t/%2e%2e/%2e%2e/secret.glb",
            "..%5csecret.glb",
            "t\\..\\..\\secret.glb",
            "/a/b/%2e%2e/x.glb",
            "http://h:8/a/b/%2E%2E/x.glb",
            "x%00.glb",
        ] {
            assert!(resolve(base, escape, false).is_err(), "{escape}");
        }
        // What is left is requested as checked: decoded dots gone, names encoded once.
        assert_eq!(
            resolve(base, "t/%2e/r%20%C3%A9.glb", false).unwrap(),
            "http://h:8/a/b/t/r%20%C3%A9.glb"
        );
        assert_eq!(
            resolve(base, "t/%2e%2e/r.glb", false).unwrap(),
            "http://h:8/a/b/r.glb"
        );
    }
}
