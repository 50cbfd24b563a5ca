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

/// Removes `.` and `..` segments; `None` when `..` climbs above the root.
fn normalize(path: &str) -> Option<String> {
    let mut out: Vec<&str> = Vec::new();
    for seg in path.split('/').skip(1) {
        match seg {
            "." => {}
            ".." => {
                out.pop()?;
            }
            s => out.push(s),
        }
    }
    Some(format!("/{}", out.join("/")))
}

/// `uri` resolved against the document at `base`, kept under `base`'s folder unless
/// `allow_outside`. Errors name the rule.
pub fn resolve(base: &str, uri: &str, allow_outside: bool) -> io::Result<String> {
    let bad = |m: String| io::Error::new(io::ErrorKind::PermissionDenied, m);
    let (origin, path) =
        split(base).ok_or_else(|| bad(format!("{base:?} is not an http(s) URL")))?;
    let folder = &path[..path.rfind('/').map_or(0, |i| i + 1)];
    let uri_path = uri.find(['?', '#']).map_or(uri, |i| &uri[..i]);
    let (o, p) = if is_url(uri) {
        split(uri).ok_or_else(|| bad(format!("{uri:?} is not a URL")))?
    } else if uri_path.starts_with('/') {
        (origin, uri_path)
    } else {
        let joined = format!("{folder}{uri_path}");
        let p = normalize(&joined)
            .ok_or_else(|| bad(format!("{uri:?} climbs above the host's root")))?;
        return check(origin, folder, &p, allow_outside, uri);
    };
    let p = normalize(p).ok_or_else(|| bad(format!("{uri:?} climbs above the host's root")))?;
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
}
