//! Writing files so that a failure never loses data: the output goes to a temporary file in
//! the destination's folder, is flushed and synced, and is renamed over the destination only
//! when complete. An interrupted or failed write leaves the previous file as it was; writing
//! over one of the run's input files is refused before anything is written.

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Refuses `out` when it names the same file as one of `inputs` (same device and inode, so
/// links and different spellings of the path count). An output that does not exist yet, or an
/// input that does not exist, never conflicts.
pub fn refuse_overwriting_inputs(out: &Path, inputs: &[&Path]) -> io::Result<()> {
    let Ok(o) = std::fs::metadata(out) else {
        return Ok(());
    };
    for input in inputs {
        let Ok(i) = std::fs::metadata(input) else {
            continue;
        };
        if same_file(&o, &i) {
            return Err(io::Error::new(
                io::ErrorKind::AlreadyExists,
                format!("refusing to write over the input file {}", input.display()),
            ));
        }
    }
    Ok(())
}

#[cfg(unix)]
fn same_file(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    a.dev() == b.dev() && a.ino() == b.ino()
}

#[cfg(not(unix))]
fn same_file(_: &std::fs::Metadata, _: &std::fs::Metadata) -> bool {
    false
}

/// Where [`write_atomic`] really writes `path`, and the permissions the new file keeps: a
/// symlink is followed (its target is replaced and the link stays), an existing regular file
/// keeps its permissions, and anything else that exists there (a device such as `/dev/null`,
/// a FIFO, a directory) is refused — renaming over it would replace the node itself.
fn destination(path: &Path) -> io::Result<(PathBuf, Option<std::fs::Permissions>)> {
    let link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    let target = if link {
        std::fs::canonicalize(path)?
    } else {
        path.to_owned()
    };
    match std::fs::metadata(&target) {
        Ok(m) if m.is_file() => Ok((target, Some(m.permissions()))),
        Ok(_) => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} exists and is not a regular file (a device, FIFO or directory); splatgl \
                 writes regular files only (`-o -` writes a PNG to standard output)",
                path.display()
            ),
        )),
        Err(_) => Ok((target, None)),
    }
}

/// A temporary name beside `path`: `.NAME.splatgl-tmp-PID-N`.
fn temp_path(path: &Path) -> io::Result<PathBuf> {
    static N: AtomicU64 = AtomicU64::new(0);
    let name = path.file_name().ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{}: not a file name", path.display()),
        )
    })?;
    let tmp = format!(
        ".{}.splatgl-tmp-{}-{}",
        name.to_string_lossy(),
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    );
    Ok(path.with_file_name(tmp))
}

/// Writes `path` through `fill`, atomically (module docs). `inputs` are files the output must
/// not replace ([`refuse_overwriting_inputs`]). If `fill` fails, nothing at `path` changes and
/// the temporary file is removed. Errors are the OS's (callers name `path`).
pub fn write_atomic(
    path: &Path,
    inputs: &[&Path],
    fill: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    refuse_overwriting_inputs(path, inputs)?;
    let (path, permissions) = destination(path)?;
    let path = path.as_path();
    let tmp = temp_path(path)?;
    let file = OpenOptions::new().write(true).create_new(true).open(&tmp)?;
    // Removes the temporary file on every way out but success, a panic in `fill` included.
    struct Cleanup<'p>(&'p Path, bool);
    impl Drop for Cleanup<'_> {
        fn drop(&mut self) {
            if !self.1 {
                std::fs::remove_file(self.0).ok();
            }
        }
    }
    let mut cleanup = Cleanup(&tmp, false);
    let result = (|| {
        if let Some(p) = permissions {
            file.set_permissions(p)?;
        }
        let mut w = BufWriter::new(file);
        fill(&mut w)?;
        {
            let file: File = w.into_inner().map_err(|e| e.into_error())?;
            file.sync_all()?;
        } // closed before the rename (Windows cannot rename a file that is open)
        std::fs::rename(&tmp, path)
    })();
    result?;
    cleanup.1 = true;
    // Make the rename itself durable (best effort: not every platform can open a folder).
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
    if let Ok(d) = File::open(dir.unwrap_or(Path::new("."))) {
        d.sync_all().ok();
    }
    Ok(())
}

/// [`write_atomic`] of a byte buffer.
pub fn write_bytes_atomic(path: &Path, inputs: &[&Path], bytes: &[u8]) -> io::Result<()> {
    write_atomic(path, inputs, |w| w.write_all(bytes))
}
