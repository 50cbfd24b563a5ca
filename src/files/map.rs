//! Scene files read at the speed of memory: a regular file is memory-mapped (read-only,
//! private) instead of copied into a buffer, so a loader parses straight from the page cache
//! into its final arrays. Standard input (`-`) and pipes cannot be mapped; they are read into
//! memory with the same byte limit.
//!
//! The contract is [`super::read_bounded`]'s: [`super::open_regular`] first (FIFOs, devices,
//! directories fail at once), then the size against the limit **before** mapping, so a file
//! larger than `limits.max_bytes` is refused without a byte being touched.
//!
//! Memory: pages of a mapping count in the process's resident set once touched. A decoder that
//! reads each byte once (the binary PLY rows) hands the part it has finished to
//! [`release_consumed`], which drops those pages from the process (`MADV_DONTNEED`: for a
//! read-only file mapping the data stays in the page cache and a later read faults it back
//! in, so nothing is lost). Peak memory of a load is then the cloud plus a few blocks of the
//! file, not the cloud plus the whole file. The call is a no-op for bytes that are not a live
//! mapping (an owned buffer would be zeroed by `MADV_DONTNEED`, so it is never advised).
//!
//! A file truncated by another process while it is mapped makes the reading thread fault
//! (`SIGBUS`): the usual trade of every mapping reader (ripgrep, plyfile's `mmap=True`). So
//! the library maps only when asked (`LoadOptions::memory_map`; the `splatgl` command asks),
//! and `SPLATGL_NO_MMAP=1` reads into memory even then.

use std::io;
use std::ops::Deref;
use std::path::Path;
use std::sync::Mutex;

/// The environment variable that turns memory mapping off (any non-empty value but `0`).
pub const NO_MMAP_ENV: &str = "SPLATGL_NO_MMAP";

/// The bytes of a scene file: mapped, or read into memory.
#[derive(Debug)]
pub enum FileBytes {
    /// A read-only private mapping of a regular file.
    Mapped(Mapping),
    /// Bytes read into memory (standard input, an empty file, or mapping turned off).
    Read(Vec<u8>),
}

impl Deref for FileBytes {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        match self {
            FileBytes::Mapped(m) => &m.map,
            FileBytes::Read(v) => v,
        }
    }
}

impl FileBytes {
    /// Whether the bytes are a memory mapping.
    pub fn is_mapped(&self) -> bool {
        matches!(self, FileBytes::Mapped(_))
    }
}

/// A live mapping, registered so that `release_consumed` knows which byte ranges it may
/// advise; unregistered when dropped.
#[derive(Debug)]
pub struct Mapping {
    map: memmap2::Mmap,
}

/// Start and length of every live [`Mapping`].
static LIVE: Mutex<Vec<(usize, usize)>> = Mutex::new(Vec::new());

fn live() -> std::sync::MutexGuard<'static, Vec<(usize, usize)>> {
    LIVE.lock().unwrap_or_else(|p| p.into_inner())
}

impl Mapping {
    fn new(map: memmap2::Mmap) -> Mapping {
        live().push((map.as_ptr() as usize, map.len()));
        Mapping { map }
    }
}

impl Drop for Mapping {
    fn drop(&mut self) {
        let start = self.map.as_ptr() as usize;
        live().retain(|&(s, _)| s != start);
    }
}

fn mapping_off() -> bool {
    std::env::var_os(NO_MMAP_ENV).is_some_and(|v| !v.is_empty() && v != "0")
}

/// A regular file of at most `limit` bytes, memory-mapped (or read, see [`NO_MMAP_ENV`]);
/// `-` reads standard input up to `limit` bytes. Errors name `what` and the limit.
pub fn map_bounded(path: &Path, limit: u64, what: &str) -> io::Result<FileBytes> {
    if path.as_os_str() == "-" {
        return read_stdin_bounded(limit, what).map(FileBytes::Read);
    }
    let (file, size) = super::open_regular(path, what)?;
    if size > limit {
        return Err(super::too_large(
            what,
            size,
            limit,
            "limits.max_bytes, --max-bytes",
        ));
    }
    if size == 0 || mapping_off() {
        return super::read_at_most(file, limit, what).map(FileBytes::Read);
    }
    // SAFETY: the mapping is read-only and private; the file is a regular file checked on the
    // open handle. Another process truncating it while mapped is the documented SIGBUS risk
    // of every mapping reader (module docs, `SPLATGL_NO_MMAP`).
    let map = match unsafe { memmap2::MmapOptions::new().map(&file) } {
        Ok(m) => m,
        // Some file systems cannot map: read instead.
        Err(_) => return super::read_at_most(file, limit, what).map(FileBytes::Read),
    };
    if map.len() as u64 > limit {
        return Err(super::too_large(
            what,
            map.len() as u64,
            limit,
            "limits.max_bytes, --max-bytes",
        ));
    }
    // Sequential read-ahead: the decoders walk the file front to back (in parallel blocks).
    #[cfg(unix)]
    let _ = map.advise(memmap2::Advice::Sequential);
    Ok(FileBytes::Mapped(Mapping::new(map)))
}

/// [`map_bounded`] when `map` is set, else the same checks and [`super::read_bounded`]'s
/// read into memory (`-`: standard input either way).
pub fn read_file_bytes(path: &Path, limit: u64, what: &str, map: bool) -> io::Result<FileBytes> {
    if map {
        map_bounded(path, limit, what)
    } else if path.as_os_str() == "-" {
        read_stdin_bounded(limit, what).map(FileBytes::Read)
    } else {
        super::read_bounded(path, limit, what).map(FileBytes::Read)
    }
}

/// Reads standard input up to `limit` bytes; more is an error naming `what`.
pub fn read_stdin_bounded(limit: u64, what: &str) -> io::Result<Vec<u8>> {
    super::read_at_most(io::stdin().lock(), limit, what)
}

/// Tells the kernel that a decoder has finished with `bytes` and will not read them again:
/// if they lie inside a live [`Mapping`], the whole pages among them leave the process's
/// resident set (`MADV_DONTNEED`; the file's data stays in the page cache). Bytes outside a
/// mapping are left alone. Only for data that is read once; a later read is still correct
/// (the page faults back in from the file), only slower.
pub(crate) fn release_consumed(bytes: &[u8]) {
    if bytes.is_empty() {
        return;
    }
    let (start, end) = (
        bytes.as_ptr() as usize,
        bytes.as_ptr() as usize + bytes.len(),
    );
    let inside = live().iter().any(|&(s, len)| s <= start && end <= s + len);
    if !inside {
        return;
    }
    // SAFETY: [start, end) lies within a live read-only private file mapping (checked above
    // under the registry's lock; a mapping is unregistered before it is unmapped, and the
    // caller's borrow of `bytes` keeps it alive); DONTNEED on such a mapping only drops pages
    // that a later access re-reads from the file.
    unsafe { advise_pages(start, end, PageAdvice::DontNeed) }
}

/// What [`advise_pages`] tells the kernel.
#[derive(Debug, Clone, Copy)]
enum PageAdvice {
    /// `MADV_DONTNEED` (unix).
    DontNeed,
    /// `MADV_HUGEPAGE` (Linux).
    HugePage,
}

/// `madvise` on the whole pages of `[start, end)`; a no-op where the advice does not exist
/// (no `madvise` off unix, no huge pages off Linux).
///
/// # Safety
/// The range must lie in memory the caller owns or a live mapping, and the advice must not
/// lose data the caller will read (`DontNeed` only on read-only file mappings).
unsafe fn advise_pages(start: usize, end: usize, advice: PageAdvice) {
    let Some((first, last)) = whole_pages(start, end) else {
        return;
    };
    #[cfg(unix)]
    {
        let flag = match advice {
            PageAdvice::DontNeed => libc::MADV_DONTNEED,
            #[cfg(target_os = "linux")]
            PageAdvice::HugePage => libc::MADV_HUGEPAGE,
            #[cfg(not(target_os = "linux"))]
            PageAdvice::HugePage => return,
        };
        // SAFETY: per this function's contract.
        unsafe {
            libc::madvise(first as *mut libc::c_void, last - first, flag);
        }
    }
    #[cfg(not(unix))]
    let _ = (first, last, advice);
}

/// The whole pages inside the address range `[start, end)`, if any.
fn whole_pages(start: usize, end: usize) -> Option<(usize, usize)> {
    let page = page_size();
    let (first, last) = (start.div_ceil(page) * page, end / page * page);
    (last > first).then_some((first, last))
}

fn page_size() -> usize {
    #[cfg(unix)]
    {
        // SAFETY: sysconf has no preconditions.
        let p = unsafe { libc::sysconf(libc::_SC_PAGESIZE) };
        if p > 0 {
            return p as usize;
        }
    }
    4096
}

/// Asks for transparent huge pages on a large, freshly allocated output array before it is
/// filled (`MADV_HUGEPAGE`): 512× fewer page faults where the kernel's THP mode is `madvise`
/// (the default on Debian and Ubuntu); no effect where THP is off or `always`, nor off Linux.
pub(crate) fn advise_huge<T>(v: &mut [T]) {
    let bytes = std::mem::size_of_val(v);
    if bytes < (4 << 20) {
        return;
    }
    let start = v.as_mut_ptr() as usize;
    // SAFETY: the range lies inside `v`'s allocation; MADV_HUGEPAGE changes no contents.
    unsafe { advise_pages(start, start + bytes, PageAdvice::HugePage) }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_file(name: &str, bytes: &[u8]) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("splatgl-map-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let p = d.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }

    #[test]
    fn released_pages_of_a_mapping_still_read_the_file() {
        let data: Vec<u8> = (0..(1 << 20)).map(|i| (i * 7 % 251) as u8).collect();
        let p = temp_file("release.bin", &data);
        let m = map_bounded(&p, 1 << 30, "the scene file").unwrap();
        assert!(m.is_mapped());
        assert_eq!(&m[..], &data[..]);
        release_consumed(&m[100..900_000]);
        assert_eq!(&m[..], &data[..], "a released page reads the file again");
    }

    /// The process's resident file-backed memory in bytes (Linux).
    #[cfg(target_os = "linux")]
    fn rss_file_bytes() -> u64 {
        let status = std::fs::read_to_string("/proc/self/status").unwrap();
        let line = status.lines().find(|l| l.starts_with("RssFile:")).unwrap();
        let kb: u64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
        kb * 1024
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn released_pages_leave_the_resident_set() {
        const MB: usize = 1 << 20;
        let data: Vec<u8> = (0..48 * MB).map(|i| (i % 253) as u8).collect();
        let p = temp_file("resident.bin", &data);
        drop(data);
        let m = map_bounded(&p, 1 << 30, "the scene file").unwrap();
        let before = rss_file_bytes();
        let sum: u64 = m.iter().step_by(4096).map(|&b| b as u64).sum();
        assert!(sum > 0);
        let touched = rss_file_bytes();
        assert!(
            touched >= before + 40 * MB as u64,
            "touching 48 MB of the mapping: {before} → {touched} bytes resident"
        );
        release_consumed(&m);
        let released = rss_file_bytes();
        assert!(
            released + 40 * MB as u64 <= touched,
            "after release_consumed: {touched} → {released} bytes resident"
        );
        std::fs::remove_file(&p).ok();
    }

    #[test]
    fn owned_buffers_are_never_advised() {
        let v: Vec<u8> = vec![5; 1 << 20];
        release_consumed(&v);
        assert!(v.iter().all(|&b| b == 5), "DONTNEED would have zeroed them");
    }

    #[test]
    fn the_limit_is_checked_before_mapping() {
        let p = temp_file("limit.bin", &[1; 100]);
        let e = map_bounded(&p, 99, "the scene file").unwrap_err();
        assert!(e.to_string().contains("more than the limit of 99"), "{e}");
    }

    #[test]
    fn empty_files_are_read_not_mapped() {
        let p = temp_file("empty.bin", &[]);
        let m = map_bounded(&p, 10, "the scene file").unwrap();
        assert!(!m.is_mapped());
        assert!(m.is_empty());
    }
}
