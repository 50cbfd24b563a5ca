//! Clouds from C: loaded from a file (with the library's limits and containment), or built
//! from the host's arrays (checked like a loaded cloud).

use std::ffi::{CStr, c_char, c_int};
use std::path::{Path, PathBuf};

use super::error::{CError, SPLATGL_ERROR_LOAD, call, status};
use splatgl::cloud::{MAX_SH_DEGREE, SplatCloud, sh_coeff_count};
use splatgl::files::Limits;
use splatgl::load::{LoadOptions, load_path};

/// A cloud of splats in host memory (opaque). Made by `splatgl_cloud_load`,
/// `splatgl_cloud_load_with` or `splatgl_cloud_from_arrays`; freed by `splatgl_cloud_free`.
/// A cloud may be freed as soon as it is uploaded (the renderer keeps what it needs), and
/// used from any thread.
#[derive(Debug)]
pub struct SplatglCloud {
    cloud: SplatCloud,
}

impl SplatglCloud {
    pub(super) fn cloud(&self) -> &SplatCloud {
        &self.cloud
    }
}

/// Options of `splatgl_cloud_load_with`. Fill with `splatgl_load_options_default` first, then
/// change what you need (fields added later keep their defaults that way).
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct SplatglLoadOptions {
    /// Most splats the file may produce (default 2^25).
    pub max_splats: u64,
    /// Most bytes read from files: the scene file and its external buffers (default 4 GiB).
    pub max_bytes: u64,
    /// Most bytes compressed data may inflate to (default 4 GiB).
    pub max_decompressed_bytes: u64,
    /// Non-zero: a splat with a non-finite or out-of-range value fails the load instead of
    /// being dropped with a warning (default 0).
    pub strict: c_int,
    /// Non-zero: external glTF buffers may lie outside the file's folder (default 0: a file
    /// from the internet cannot make splatgl read the rest of the disk).
    pub allow_outside_paths: c_int,
    /// Non-zero: memory-map the file instead of reading it (default 0: a file truncated by
    /// another process while mapped kills the process with SIGBUS).
    pub memory_map: c_int,
    /// `NULL` (the default), or a folder the file must lie inside (after resolving symbolic
    /// links and `..`): the host's own containment rule for paths that come from users.
    pub root: *const c_char,
}

impl Default for SplatglLoadOptions {
    fn default() -> Self {
        SplatglLoadOptions {
            max_splats: Limits::DEFAULT_MAX_SPLATS,
            max_bytes: Limits::DEFAULT_MAX_BYTES,
            max_decompressed_bytes: Limits::DEFAULT_MAX_DECOMPRESSED_BYTES,
            strict: 0,
            allow_outside_paths: 0,
            memory_map: 0,
            root: std::ptr::null(),
        }
    }
}

/// Writes the default options into `*out`.
///
/// # Safety
/// `out` is `NULL` or points to writable memory for one `SplatglLoadOptions`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn splatgl_load_options_default(out: *mut SplatglLoadOptions) -> c_int {
    status(|| {
        // SAFETY: the caller's pointer, checked for NULL by `as_mut`.
        let out = unsafe { out.as_mut() }.ok_or_else(|| CError::null("out"))?;
        *out = SplatglLoadOptions::default();
        Ok(())
    })
}

/// A path argument as a Rust path: on Unix the bytes as given (UTF-8 or not), on Windows
/// UTF-8 (converted to the UTF-16 Windows uses; other bytes are refused).
///
/// # Safety
/// `p` is `NULL` or a NUL-terminated string.
unsafe fn path_arg(p: *const c_char, what: &str) -> Result<PathBuf, CError> {
    if p.is_null() {
        return Err(CError::null(what));
    }
    // SAFETY: non-NULL and NUL-terminated (the caller's contract).
    let bytes = unsafe { CStr::from_ptr(p) }.to_bytes();
    if bytes.is_empty() {
        return Err(CError::invalid(format!("{what} is empty")));
    }
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        Ok(PathBuf::from(std::ffi::OsStr::from_bytes(bytes)))
    }
    #[cfg(not(unix))]
    match std::str::from_utf8(bytes) {
        Ok(s) => Ok(PathBuf::from(s)),
        Err(e) => Err(CError::invalid(format!("{what} is not UTF-8 ({e})"))),
    }
}

/// Refuses `path` unless it lies inside `root` (both resolved).
fn check_contained(path: &Path, root: &Path) -> Result<(), CError> {
    let resolve = |p: &Path| {
        p.canonicalize()
            .map_err(|e| CError::new(SPLATGL_ERROR_LOAD, format!("{}: {e}", p.display())))
    };
    let (p, r) = (resolve(path)?, resolve(root)?);
    if !p.starts_with(&r) {
        return Err(CError::new(
            SPLATGL_ERROR_LOAD,
            format!(
                "{}: outside the allowed folder {} (SplatglLoadOptions.root)",
                path.display(),
                root.display()
            ),
        ));
    }
    Ok(())
}

fn store(out: *mut *mut SplatglCloud, cloud: SplatCloud) {
    let boxed = Box::into_raw(Box::new(SplatglCloud { cloud }));
    // SAFETY: `out` was checked non-NULL by the caller of `store`.
    unsafe { *out = boxed };
}

/// Loads a splat file of any supported format (glTF/GLB with `KHR_gaussian_splatting`, PLY,
/// SPZ, .splat, .ksplat, SOG) with the default options. On success `*out` is a new cloud.
///
/// # Safety
/// `path` is `NULL` or NUL-terminated; `out` is `NULL` or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn splatgl_cloud_load(
    path: *const c_char,
    out: *mut *mut SplatglCloud,
) -> c_int {
    let opts = SplatglLoadOptions::default();
    // SAFETY: the caller's contract, passed on; `opts` is a valid local.
    unsafe { splatgl_cloud_load_with(path, &opts, out) }
}

/// Loads a splat file with `options` (`NULL`: the defaults). On success `*out` is a new cloud;
/// on failure `*out` is left as it was.
///
/// # Safety
/// `path` is `NULL` or NUL-terminated; `options` is `NULL` or a valid options struct whose
/// `root` is `NULL` or NUL-terminated; `out` is `NULL` or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn splatgl_cloud_load_with(
    path: *const c_char,
    options: *const SplatglLoadOptions,
    out: *mut *mut SplatglCloud,
) -> c_int {
    status(|| {
        if out.is_null() {
            return Err(CError::null("out"));
        }
        // SAFETY: the caller's contract.
        let path = unsafe { path_arg(path, "path") }?;
        // SAFETY: NULL or a valid struct (the caller's contract).
        let o = unsafe { options.as_ref() }.copied().unwrap_or_default();
        if !o.root.is_null() {
            // SAFETY: non-NULL and NUL-terminated (the caller's contract).
            let root = unsafe { path_arg(o.root, "options.root") }?;
            check_contained(&path, &root)?;
        }
        let opts = LoadOptions {
            strict: o.strict != 0,
            allow_outside_paths: o.allow_outside_paths != 0,
            memory_map: o.memory_map != 0,
            limits: Limits {
                max_splats: o.max_splats,
                max_bytes: o.max_bytes,
                max_decompressed_bytes: o.max_decompressed_bytes,
                ..Limits::default()
            },
            ..LoadOptions::default()
        };
        let scene =
            load_path(&path, &opts).map_err(|e| CError::new(SPLATGL_ERROR_LOAD, e.to_string()))?;
        store(out, scene.cloud);
        Ok(())
    })
}

/// Reads `n * width` floats from `p` (`what` names the argument in errors).
///
/// # Safety
/// `p` is `NULL` or points to `n * width` readable floats.
unsafe fn floats<'a>(
    p: *const f32,
    n: usize,
    width: usize,
    what: &str,
) -> Result<&'a [f32], CError> {
    if n == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(CError::null(what));
    }
    let len = n
        .checked_mul(width)
        .ok_or_else(|| CError::invalid(format!("{what}: {n} × {width} floats overflow")))?;
    // SAFETY: non-NULL, `len` readable floats (the caller's contract).
    Ok(unsafe { std::slice::from_raw_parts(p, len) })
}

/// Builds a cloud from the host's arrays (copied; the arrays may be freed afterwards):
/// `n` splats with `positions` (3n floats, x y z), `scales` (3n, linear standard deviations
/// ≥ 0), `rotations_xyzw` (4n, quaternions x y z w as in glTF; normalised here, a zero or
/// non-finite one is an error), `opacities` (n, linear in [0, 1]), and `sh` (n · 3 · (d+1)²
/// floats for `sh_degree` d in 0..3: per splat, per coefficient (degree-major, m = −l..l),
/// R G B; the first coefficient is the DC term, colour = 0.5 + 0.2820948 · DC). Every value is
/// checked like a loaded file's: the first bad one is an error naming the splat and field.
///
/// # Safety
/// Each array pointer is `NULL` (only when `n` is 0) or points to the floats described;
/// `out` is `NULL` or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn splatgl_cloud_from_arrays(
    n: usize,
    positions: *const f32,
    scales: *const f32,
    rotations_xyzw: *const f32,
    opacities: *const f32,
    sh_degree: c_int,
    sh: *const f32,
    out: *mut *mut SplatglCloud,
) -> c_int {
    status(|| {
        if out.is_null() {
            return Err(CError::null("out"));
        }
        let degree = u8::try_from(sh_degree)
            .ok()
            .filter(|d| *d <= MAX_SH_DEGREE)
            .ok_or_else(|| CError::invalid(format!("sh_degree {sh_degree} is not 0..3")))?;
        if n as u64 > Limits::DEFAULT_MAX_SPLATS {
            return Err(CError::invalid(format!(
                "{n} splats: at most {} (the default max_splats)",
                Limits::DEFAULT_MAX_SPLATS
            )));
        }
        let k = sh_coeff_count(degree);
        // SAFETY: the caller's contract for each array.
        let (p, s, r, o, c) = unsafe {
            (
                floats(positions, n, 3, "positions")?,
                floats(scales, n, 3, "scales")?,
                floats(rotations_xyzw, n, 4, "rotations_xyzw")?,
                floats(opacities, n, 1, "opacities")?,
                floats(sh, n, 3 * k, "sh")?,
            )
        };
        let cloud = from_arrays(n, degree, [p, s, r, o, c])?;
        store(out, cloud);
        Ok(())
    })
}

fn from_arrays(n: usize, degree: u8, [p, s, r, o, c]: [&[f32]; 5]) -> Result<SplatCloud, CError> {
    let mut cloud = SplatCloud::with_capacity(degree, n);
    let k = cloud.coeffs_per_splat();
    cloud
        .positions
        .extend(p.chunks_exact(3).map(|v| [v[0], v[1], v[2]]));
    cloud
        .scales
        .extend(s.chunks_exact(3).map(|v| [v[0], v[1], v[2]]));
    for (i, q) in r.chunks_exact(4).enumerate() {
        let len = q.iter().map(|v| v * v).sum::<f32>().sqrt();
        if !(len.is_finite() && len > 0.0) {
            return Err(CError::invalid(format!(
                "splat {i}: rotation {q:?} is zero or not finite"
            )));
        }
        cloud
            .rotations
            .push([q[0] / len, q[1] / len, q[2] / len, q[3] / len]);
    }
    cloud.opacities.extend_from_slice(o);
    cloud
        .sh
        .extend(c.chunks_exact(3).map(|v| [v[0], v[1], v[2]]));
    debug_assert_eq!(cloud.sh.len(), n * k);
    cloud
        .validate()
        .map_err(|v| CError::invalid(v.to_string()))?;
    Ok(cloud)
}

/// Splats in `cloud` (0 for `NULL`).
///
/// # Safety
/// `cloud` is `NULL` or a live cloud.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn splatgl_cloud_len(cloud: *const SplatglCloud) -> usize {
    call(0, || {
        // SAFETY: NULL or live (the caller's contract).
        Ok(unsafe { cloud.as_ref() }.map_or(0, |c| c.cloud.len()))
    })
    .0
}

/// The SH degree of `cloud` (0..3), or `SPLATGL_ERROR_NULL_POINTER`.
///
/// # Safety
/// `cloud` is `NULL` or a live cloud.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn splatgl_cloud_sh_degree(cloud: *const SplatglCloud) -> c_int {
    let (d, code) = call(0, || {
        // SAFETY: NULL or live (the caller's contract).
        let c = unsafe { cloud.as_ref() }.ok_or_else(|| CError::null("cloud"))?;
        Ok(c_int::from(c.cloud.sh_degree))
    });
    if code == 0 { d } else { code }
}

/// Frees a cloud (`NULL` is ignored). Uploaded copies stay on the GPU.
///
/// # Safety
/// `cloud` is `NULL` or a cloud from this library not yet freed.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn splatgl_cloud_free(cloud: *mut SplatglCloud) {
    status(|| {
        if !cloud.is_null() {
            // SAFETY: made by `Box::into_raw` in `store`, not freed yet (the caller's contract).
            drop(unsafe { Box::from_raw(cloud) });
        }
        Ok(())
    });
}
