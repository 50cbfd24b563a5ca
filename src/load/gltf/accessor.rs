//! Accessor decoding: every component type, normalized or not, any `byteStride`, sparse
//! accessors. Sizes are checked against the buffer before anything is allocated.
//!
//! The `gltf` crate's readers check neither the component type nor normalization, so this
//! module decodes the bytes itself from `data_type()`, `normalized()`, stride and offset.

use crate::load::finding::Finding;
use gltf::accessor::{DataType, Dimensions};

/// A decoded accessor: `count × dims` floats, plus how they were stored.
#[derive(Debug, Clone)]
pub struct Decoded {
    /// Values, element-major.
    pub data: Vec<f32>,
    /// Components per element.
    pub dims: usize,
    /// Stored component type.
    pub component: DataType,
    /// Whether integer values were normalized.
    pub normalized: bool,
    /// A glTF 2.0 alignment rule the layout breaks (data still decoded).
    pub misaligned: Option<String>,
}

impl Decoded {
    /// Number of elements.
    pub fn count(&self) -> usize {
        self.data.len().checked_div(self.dims).unwrap_or(0)
    }
    /// Element `i` as an array of `N` components.
    pub fn get<const N: usize>(&self, i: usize) -> [f32; N] {
        std::array::from_fn(|k| self.data[i * self.dims + k])
    }
}

/// Human name of a component type, as in the spec's tables.
pub fn component_name(t: DataType, normalized: bool) -> String {
    let base = match t {
        DataType::I8 => "signed byte",
        DataType::U8 => "unsigned byte",
        DataType::I16 => "signed short",
        DataType::U16 => "unsigned short",
        DataType::U32 => "unsigned int",
        DataType::F32 => "float",
    };
    if normalized {
        format!("{base} normalized")
    } else {
        base.to_owned()
    }
}

/// Reads one component at the start of `b` as f32 (normalized per glTF 2.0 §3.11).
#[inline]
fn read(b: &[u8], t: DataType, norm: bool) -> f32 {
    match t {
        DataType::I8 => {
            let v = b[0] as i8 as f32;
            if norm { (v / 127.0).max(-1.0) } else { v }
        }
        DataType::U8 => {
            let v = b[0] as f32;
            if norm { v / 255.0 } else { v }
        }
        DataType::I16 => {
            let v = i16::from_le_bytes([b[0], b[1]]) as f32;
            if norm { (v / 32767.0).max(-1.0) } else { v }
        }
        DataType::U16 => {
            let v = u16::from_le_bytes([b[0], b[1]]) as f32;
            if norm { v / 65535.0 } else { v }
        }
        DataType::U32 => {
            let v = u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64;
            if norm {
                (v / u32::MAX as f64) as f32
            } else {
                v as f32
            }
        }
        DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
    }
}

fn dims_of(d: Dimensions) -> Option<usize> {
    match d {
        Dimensions::Scalar => Some(1),
        Dimensions::Vec2 => Some(2),
        Dimensions::Vec3 => Some(3),
        Dimensions::Vec4 => Some(4),
        _ => None,
    }
}

/// The bytes of a buffer view, bounds-checked.
pub(super) fn view_bytes<'b>(
    view: &gltf::buffer::View,
    buffers: &'b [Vec<u8>],
    path: &str,
) -> Result<&'b [u8], Finding> {
    let buf = buffers
        .get(view.buffer().index())
        .map(Vec::as_slice)
        .unwrap_or(&[]);
    let (off, len) = (view.offset(), view.length());
    off.checked_add(len)
        .filter(|&end| end <= buf.len())
        .map(|end| &buf[off..end])
        .ok_or_else(|| {
            Finding::fatal(
                path,
                format!(
                    "bufferViews[{}] (offset {off}, length {len}) exceeds buffers[{}] ({} bytes)",
                    view.index(),
                    view.buffer().index(),
                    buf.len()
                ),
            )
        })
}

/// A blocking finding at `path` about accessor `acc`.
fn accessor_error(acc: &gltf::Accessor, path: &str, msg: String) -> Finding {
    Finding::fatal(path, format!("accessors[{}]: {msg}", acc.index()))
}

/// Decodes accessor `acc`. `path` names the attribute in findings. `budget` is the number of
/// decoded values the whole document may still produce (bounded by the input size); it is
/// checked before allocating and charged after.
pub fn decode(
    acc: &gltf::Accessor,
    buffers: &[Vec<u8>],
    path: &str,
    budget: &std::cell::Cell<u64>,
) -> Result<Decoded, Finding> {
    let fail = |msg: String| accessor_error(acc, path, msg);
    let dims = dims_of(acc.dimensions()).ok_or_else(|| {
        fail(format!(
            "type {:?} is not SCALAR/VEC2/VEC3/VEC4",
            acc.dimensions()
        ))
    })?;
    let (t, norm) = (acc.data_type(), acc.normalized());
    let count = acc.count();
    let values = count as u128 * dims as u128;
    if values > budget.get() as u128 {
        return Err(fail(format!(
            "count {count} would decode to more values than this file can justify ({} left of its budget)",
            budget.get()
        )));
    }
    budget.set(budget.get() - values as u64);
    let (mut data, misaligned) = match acc.view() {
        Some(view) => read_view(acc, &view, dims, buffers, path)?,
        None => (vec![0.0; count * dims], None),
    };
    if let Some(sparse) = acc.sparse() {
        apply_sparse(&sparse, &mut data, dims, t, norm, count, buffers, path)
            .map_err(|m| fail(format!("sparse: {m}")))?;
    }
    Ok(Decoded {
        data,
        dims,
        component: t,
        normalized: norm,
        misaligned,
    })
}

/// The values of accessor `acc` (`dims` components per element) read from its bufferView
/// `view`, with the glTF 2.0 alignment rule the layout breaks, if any. The stride and the
/// extent of the elements are checked against the view before anything is allocated.
fn read_view(
    acc: &gltf::Accessor,
    view: &gltf::buffer::View,
    dims: usize,
    buffers: &[Vec<u8>],
    path: &str,
) -> Result<(Vec<f32>, Option<String>), Finding> {
    let fail = |msg: String| accessor_error(acc, path, msg);
    let (t, norm) = (acc.data_type(), acc.normalized());
    let csize = t.size();
    let esize = dims * csize;
    let count = acc.count();
    let bytes = view_bytes(view, buffers, path)?;
    let stride = view.stride().unwrap_or(esize);
    // glTF 2.0 §3.6.2.4: offsets are multiples of the component size, and vertex
    // attribute elements start on 4-byte boundaries.
    let offset = view.offset() as u128 + acc.offset() as u128;
    let misaligned = if !offset.is_multiple_of(csize as u128) {
        Some(format!(
            "byte offset {offset} is not a multiple of the component size {csize}"
        ))
    } else if !offset.is_multiple_of(4) || !stride.is_multiple_of(4) {
        Some(format!(
            "vertex attribute elements must start on 4-byte boundaries (offset {offset}, stride {stride})"
        ))
    } else {
        None
    };
    if stride < esize {
        return Err(fail(format!(
            "byteStride {stride} is smaller than the element size {esize}"
        )));
    }
    let start = acc.offset();
    // u128: no count, stride or offset from the file can overflow this.
    let needed = match count {
        0 => 0,
        n => (n as u128 - 1) * stride as u128 + start as u128 + esize as u128,
    };
    if needed > bytes.len() as u128 {
        return Err(fail(format!(
            "count {count} × stride {stride} from offset {start} needs {needed} bytes; bufferViews[{}] has {}",
            view.index(),
            bytes.len()
        )));
    }
    let mut out = Vec::with_capacity(count * dims);
    for i in 0..count {
        let e = &bytes[start + i * stride..];
        for k in 0..dims {
            out.push(read(&e[k * csize..], t, norm));
        }
    }
    Ok((out, misaligned))
}

#[allow(clippy::too_many_arguments)]
fn apply_sparse(
    sparse: &gltf::accessor::sparse::Sparse,
    data: &mut [f32],
    dims: usize,
    t: DataType,
    norm: bool,
    count: usize,
    buffers: &[Vec<u8>],
    path: &str,
) -> Result<(), String> {
    use gltf::accessor::sparse::IndexType;
    let n = sparse.count();
    if n > count {
        return Err(format!("count {n} exceeds the accessor count {count}"));
    }
    let idx = sparse.indices();
    let isize = match idx.index_type() {
        IndexType::U8 => 1,
        IndexType::U16 => 2,
        IndexType::U32 => 4,
    };
    let ib = view_bytes(&idx.view(), buffers, path).map_err(|f| f.message)?;
    let ioff = idx.offset();
    if ioff as u128 + n as u128 * isize as u128 > ib.len() as u128 {
        return Err(format!("{n} indices do not fit their bufferView"));
    }
    let vals = sparse.values();
    let vb = view_bytes(&vals.view(), buffers, path).map_err(|f| f.message)?;
    let voff = vals.offset();
    let esize = dims * t.size();
    if voff as u128 + n as u128 * esize as u128 > vb.len() as u128 {
        return Err(format!("{n} values do not fit their bufferView"));
    }
    let mut prev: Option<usize> = None;
    for s in 0..n {
        let b = &ib[ioff + s * isize..];
        let i = match isize {
            1 => b[0] as usize,
            2 => u16::from_le_bytes([b[0], b[1]]) as usize,
            _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
        };
        if i >= count {
            return Err(format!(
                "index {i} (entry {s}) is out of range (count {count})"
            ));
        }
        if prev.is_some_and(|p| i <= p) {
            return Err(format!("indices are not strictly increasing at entry {s}"));
        }
        prev = Some(i);
        let e = &vb[voff + s * esize..];
        for k in 0..dims {
            data[i * dims + k] = read(&e[k * t.size()..], t, norm);
        }
    }
    Ok(())
}
