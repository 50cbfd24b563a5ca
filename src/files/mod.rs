//! Bounded reads of regular files: the one way splatgl reads a file from disk (scenes, external
//! glTF buffers, `cameras.json`, images); and the containment rule for files a document names.
//!
//! A path is checked to be a regular file **before** it is opened for reading (so a FIFO cannot
//! block the open, and `/dev/zero`, a directory or a socket fail at once), opened non-blocking,
//! checked again on the open handle (the path may have been swapped in between), and its size
//! is compared with the caller's limit before a byte is read. The read itself stops one byte past
//! the limit, so a file that grows while being read cannot exceed it either.
//!
//! The API, which readers and their tests rely on:
//! - [`open_regular`]`(path, what) -> (File, size)`: the checks alone, for readers that stream
//!   or read part of a file (external glTF buffers read up to `byteLength`);
//! - [`read_bounded`]`(path, limit, what) -> Vec<u8>`: the whole file, at most `limit` bytes;
//! - `contained(base, uri, allow_outside)` / `contained_path(base, rel, allow_outside)`
//!   (crate-internal): the containment rule for files a document names, returning the
//!   canonical path to open with the two above.
//!
//! Errors are `io::Error`s whose message names `what` and the rule or limit; callers add the
//! path. [`map_bounded`] is the memory-mapped variant with the same contract ([`open_regular`]
//! first, then the size against the limit before mapping), used for scene files (`map.rs`).

mod format;
pub mod http;
mod limits;
mod map;
pub use format::Format;
pub use limits::{JsonShapeError, LimitExceeded, Limits, check_json, check_json_depth};
pub use map::{FileBytes, Mapping, NO_MMAP_ENV, map_bounded, read_file_bytes, read_stdin_bounded};
pub(crate) use map::{advise_huge, release_consumed};

use std::fs::File;
use std::io::{self, Read};
use std::path::{Path, PathBuf};

/// What a non-regular file is, for the error message.
fn kind_of(t: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
    }
    if t.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

fn not_regular(what: &str, t: std::fs::FileType) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("{what} is {} (only regular files are read)", kind_of(t)),
    )
}

/// Opens `path` for reading after checking it is a regular file, and returns the handle and
/// the file's size. `what` names the file in errors ("scene", "external buffer", …).
pub fn open_regular(path: &Path, what: &str) -> io::Result<(File, u64)> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(not_regular(what, meta.file_type()));
    }
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        // If the path became a FIFO after the check above, the open must not wait for a writer.
        options.custom_flags(libc::O_NONBLOCK);
    }
    let f = options.open(path)?;
    let meta = f.metadata()?;
    if !meta.is_file() {
        return Err(not_regular(what, meta.file_type()));
    }
    Ok((f, meta.len()))
}

/// The error for a file larger than a limit. `flag` names what raises it.
pub(crate) fn too_large(what: &str, size: u64, limit: u64, flag: &str) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("{what} is {size} bytes, more than the limit of {limit} bytes ({flag})"),
    )
}

/// Reads at most `limit` bytes of `file` (a file, standard input) into memory; more is an
/// error.
pub(crate) fn read_at_most(file: impl Read, limit: u64, what: &str) -> io::Result<Vec<u8>> {
    let mut data = Vec::new();
    file.take(limit.saturating_add(1)).read_to_end(&mut data)?;
    if data.len() as u64 > limit {
        return Err(too_large(
            what,
            data.len() as u64,
            limit,
            "limits.max_bytes, --max-bytes",
        ));
    }
    Ok(data)
}

/// Reads a whole regular file of at most `limit` bytes. Directories, FIFOs, sockets and
/// devices are errors before anything is read; so is a file whose size exceeds `limit`
/// (checked before reading, and again while reading). `what` names the file in errors.
pub fn read_bounded(path: &Path, limit: u64, what: &str) -> io::Result<Vec<u8>> {
    let (f, size) = open_regular(path, what)?;
    if size > limit {
        return Err(too_large(
            what,
            size,
            limit,
            "limits.max_bytes, --max-bytes",
        ));
    }
    read_at_most(f, limit, what)
}

/// The containment rule for files a document names by URI (glTF buffer URIs, later image
/// URIs): `uri` is percent-decoded, then [`contained_path`] applies.
pub(crate) fn contained(base: &Path, uri: &str, allow_outside: bool) -> Result<PathBuf, String> {
    let decoded = percent_decode(uri);
    contained_named(base, Path::new(&decoded), uri, allow_outside)
}

/// The containment rule for a file name taken as written (the textures beside a SOG
/// `meta.json`): `rel` is joined to `base` (the document's folder); both are canonicalised
/// (`..` resolved, symlinks followed) and the file must lie inside `base`. Absolute paths, `..`
/// escapes and symlinks pointing outside are refused with a message naming the file and the
/// rule, unless `allow_outside`. Returns the canonical path.
pub fn contained_path(base: &Path, rel: &Path, allow_outside: bool) -> Result<PathBuf, Refused> {
    contained_file(base, rel, &rel.to_string_lossy(), allow_outside)
}

fn contained_named(
    base: &Path,
    rel: &Path,
    name: &str,
    allow_outside: bool,
) -> Result<PathBuf, String> {
    contained_file(base, rel, name, allow_outside).map_err(|e| match e {
        Refused::Outside(m) | Refused::Missing(m) => m,
    })
}

/// Why [`contained_path`] gave no file.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Refused {
    /// Outside the folder (by name, or once symlinks are followed): the message names the rule.
    #[error("{0}")]
    Outside(String),
    /// Inside the folder but not there (or unreadable): the message names the path.
    #[error("{0}")]
    Missing(String),
}

impl From<Refused> for String {
    fn from(e: Refused) -> String {
        e.to_string()
    }
}

/// The containment rule, told apart from a missing file. Containment is decided before
/// existence is reported: a name that leads outside the folder is refused the same way
/// whether or not its file exists, so a document cannot probe for files outside its folder.
pub(crate) fn contained_file(
    base: &Path,
    rel: &Path,
    name: &str,
    allow_outside: bool,
) -> Result<PathBuf, Refused> {
    let how = "files a document names must lie inside its folder (allow with --allow-outside-paths / LoadOptions::allow_outside_paths)";
    if !allow_outside {
        match lexical_escape(&rel.to_string_lossy()) {
            Some(Escape::Absolute) => {
                return Err(Refused::Outside(format!(
                    "URI {name:?} is an absolute path; {how}"
                )));
            }
            Some(Escape::Up) => {
                return Err(Refused::Outside(format!(
                    "URI {name:?} resolves outside the asset's folder (its `..` climb above \
                     it); {how}"
                )));
            }
            None => {}
        }
    }
    let joined = base.join(rel);
    let canonical = joined.canonicalize();
    if allow_outside {
        return canonical.map_err(|e| Refused::Missing(format!("{}: {e}", joined.display())));
    }
    let root = base
        .canonicalize()
        .map_err(|e| Refused::Missing(format!("asset folder {}: {e}", base.display())))?;
    // A missing file is judged by the deepest part of its path that exists (a symlinked
    // folder pointing outside is outside, whether or not the file is in it).
    let (judged, missing) = match canonical {
        Ok(file) => (file, None),
        Err(e) => (
            existing_ancestor(&joined).unwrap_or_else(|| root.clone()),
            Some(format!("{}: {e}", joined.display())),
        ),
    };
    if !judged.starts_with(&root) {
        return Err(Refused::Outside(format!(
            "URI {name:?} resolves outside the asset's folder {}; {how}",
            root.display()
        )));
    }
    match missing {
        Some(m) => Err(Refused::Missing(m)),
        None => Ok(judged),
    }
}

/// The canonical form of the deepest ancestor of `path` that exists.
fn existing_ancestor(path: &Path) -> Option<PathBuf> {
    path.ancestors().skip(1).find_map(|a| a.canonicalize().ok())
}

/// How a name escapes its folder before any file is looked at.
#[derive(Debug, PartialEq, Eq)]
enum Escape {
    /// Absolute on some platform: `/x`, `\x`, `C:\x`, `C:/x`, `C:x`, `\\server\share`.
    Absolute,
    /// Its `..` components climb above the folder (`../x`, `a/../../x`, `..\x`).
    Up,
}

/// The containment rule's platform-neutral half: `name` taken the way every platform would
/// read it, with both `/` and `\` as separators and a drive letter as absolute, so a document
/// written on one system is judged the same on every other (a glTF that names `..\..\secret`
/// or `C:\x` is refused on Linux as on Windows). The file-system half (symlinks) follows in
/// [`contained_path`].
fn lexical_escape(name: &str) -> Option<Escape> {
    let b = name.as_bytes();
    let drive = b.len() >= 2 && b[0].is_ascii_alphabetic() && b[1] == b':';
    if drive || name.starts_with(['/', '\\']) {
        return Some(Escape::Absolute);
    }
    let mut depth = 0usize;
    for part in name.split(['/', '\\']) {
        match part {
            "" | "." => {}
            ".." => match depth.checked_sub(1) {
                Some(d) => depth = d,
                None => return Some(Escape::Up),
            },
            _ => depth += 1,
        }
    }
    None
}

pub(crate) fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let hex = |c: u8| (c as char).to_digit(16).map(|d| d as u8);
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%'
            && i + 2 < b.len()
            && let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2]))
        {
            out.push(h * 16 + l);
            i += 3;
            continue;
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The process's peak resident memory so far, in bytes (`VmHWM` of `/proc/self/status`;
/// `None` where there is no such file): what `convert`, `render -v` and the viewer's
/// `--bench-frames` report.
pub fn peak_memory() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_that_escape_on_any_platform_are_escapes_on_every_platform() {
        for name in [
            "/etc/passwd",
            "\\x",
            "C:\\x",
            "c:/x",
            "C:x",
            "\\\\server\\share\\x",
        ] {
            assert_eq!(lexical_escape(name), Some(Escape::Absolute), "{name}");
        }
        for name in ["../x", "..\\..\\secret", "a/../../x", "a\\..\\..\\x", ".."] {
            assert_eq!(lexical_escape(name), Some(Escape::Up), "{name}");
        }
        for name in [
            "x.bin",
            "a/../x",
            "a\\b\\..\\x",
            "./x",
            "a/./b",
            "..x",
            "x..",
        ] {
            assert_eq!(lexical_escape(name), None, "{name}");
        }
    }

    #[test]
    fn percent_decoding_keeps_invalid_escapes() {
        assert_eq!(percent_decode("a%20b%2e.bin"), "a b..bin");
        assert_eq!(percent_decode("%zz%4"), "%zz%4");
    }

    #[test]
    fn devices_and_directories_are_refused_before_reading() {
        #[cfg(unix)]
        {
            let e = read_bounded(Path::new("/dev/zero"), 1 << 20, "scene").unwrap_err();
            assert!(e.to_string().contains("character device"), "{e}");
        }
        #[cfg(windows)]
        {
            let e = read_bounded(Path::new(r"\\.\NUL"), 1 << 20, "scene").unwrap_err();
            assert!(!e.to_string().is_empty());
        }
        let e = read_bounded(Path::new("/"), 1 << 20, "scene").unwrap_err();
        assert!(e.to_string().contains("directory"), "{e}");
    }

    #[test]
    fn size_is_checked_against_the_limit() {
        let p = std::env::temp_dir().join(format!("splatgl-files-{}", std::process::id()));
        std::fs::write(&p, [7u8; 100]).unwrap();
        assert_eq!(read_bounded(&p, 100, "x").unwrap().len(), 100);
        let e = read_bounded(&p, 99, "x").unwrap_err().to_string();
        assert!(e.contains("100 bytes") && e.contains("99"), "{e}");
        std::fs::remove_file(&p).ok();
    }
}
