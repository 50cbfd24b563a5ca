//! PLY header parsing: format, elements, properties and their scalar types.

use super::PlyError;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Encoding {
    Ascii,
    Le,
    Be,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    pub(super) fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }
    pub(super) fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
    /// Reads one value at the start of `b` (which holds at least `size()` bytes).
    #[inline(always)]
    pub(super) fn read(self, b: &[u8], be: bool) -> f64 {
        macro_rules! rd {
            ($t:ty, $n:expr) => {{
                let mut a = [0u8; $n];
                a.copy_from_slice(&b[..$n]);
                if be {
                    <$t>::from_be_bytes(a) as f64
                } else {
                    <$t>::from_le_bytes(a) as f64
                }
            }};
        }
        match self {
            Scalar::I8 => b[0] as i8 as f64,
            Scalar::U8 => b[0] as f64,
            Scalar::I16 => rd!(i16, 2),
            Scalar::U16 => rd!(u16, 2),
            Scalar::I32 => rd!(i32, 4),
            Scalar::U32 => rd!(u32, 4),
            Scalar::F32 => rd!(f32, 4),
            Scalar::F64 => rd!(f64, 8),
        }
    }
}

#[derive(Debug, Clone)]
pub(super) struct Property {
    pub(super) name: String,
    pub(super) ty: Scalar,
    /// `Some(count type)` for list properties.
    pub(super) list: Option<Scalar>,
}

#[derive(Debug, Clone)]
pub(super) struct Element {
    pub(super) name: String,
    pub(super) count: u64,
    pub(super) props: Vec<Property>,
}

#[derive(Debug)]
pub(super) struct Header {
    pub(super) encoding: Encoding,
    pub(super) elements: Vec<Element>,
    /// Byte offset of the body.
    pub(super) body: usize,
    /// Number of header lines (for ASCII body line numbers).
    pub(super) lines: usize,
}

const MAX_HEADER: usize = 1 << 20;

/// A [`PlyError::Header`] at line `line`.
fn header_err(line: usize, message: String) -> PlyError {
    PlyError::Header { line, message }
}

/// Parses the header: the `ply` line, the format, the elements and their properties, up to
/// `end_header`; returns them with where the body starts.
pub(super) fn parse_header(bytes: &[u8]) -> Result<Header, PlyError> {
    let err = header_err;
    let mut pos = 0;
    let mut line_no = 0;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let line = next_line(bytes, &mut pos, &mut line_no)?;
        let words: Vec<&str> = line.split_ascii_whitespace().collect();
        if line_no == 1 {
            if words != ["ply"] {
                return Err(err(1, format!("expected 'ply', found {line:?}")));
            }
            continue;
        }
        match words.first().copied() {
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => encoding = Some(parse_format(&words, line_no)?),
            Some("element") => elements.push(parse_element(&words, line_no)?),
            Some("property") => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| err(line_no, "property before any element".into()))?;
                el.props.push(parse_property(&words, line_no)?);
            }
            Some("end_header") => break,
            Some(w) => return Err(err(line_no, format!("unknown header keyword {w:?}"))),
        }
    }
    let encoding = encoding.ok_or_else(|| err(line_no, "no 'format' line".into()))?;
    Ok(Header {
        encoding,
        elements,
        body: pos,
        lines: line_no,
    })
}

/// The header line starting at `*pos` (without its `\r\n` or `\n`), `*pos` moved past it and
/// `*line_no` counting it. An error past [`MAX_HEADER`], at the end of the file, or for a line
/// that is not text.
fn next_line<'b>(
    bytes: &'b [u8],
    pos: &mut usize,
    line_no: &mut usize,
) -> Result<&'b str, PlyError> {
    let err = header_err;
    if *pos >= bytes.len() || *pos > MAX_HEADER {
        return Err(err(*line_no + 1, "no 'end_header' line".into()));
    }
    let end = bytes[*pos..]
        .iter()
        .position(|&b| b == b'\n')
        .map(|e| *pos + e)
        .ok_or_else(|| err(*line_no + 1, "no 'end_header' line".into()))?;
    let raw = &bytes[*pos..end];
    *pos = end + 1;
    *line_no += 1;
    let line = std::str::from_utf8(raw)
        .map_err(|_| err(*line_no, "header is not ASCII text".into()))?
        .trim_end_matches('\r');
    Ok(line)
}

/// A `format ENCODING VERSION` line's encoding.
fn parse_format(words: &[&str], line_no: usize) -> Result<Encoding, PlyError> {
    Ok(match words.get(1).copied() {
        Some("ascii") => Encoding::Ascii,
        Some("binary_little_endian") => Encoding::Le,
        Some("binary_big_endian") => Encoding::Be,
        other => {
            return Err(header_err(
                line_no,
                format!(
                    "format {other:?}: expected ascii, binary_little_endian or binary_big_endian"
                ),
            ));
        }
    })
}

/// An `element NAME COUNT` line, as an element without properties yet.
fn parse_element(words: &[&str], line_no: usize) -> Result<Element, PlyError> {
    let err = header_err;
    let (Some(name), Some(count), None) = (words.get(1), words.get(2), words.get(3)) else {
        return Err(err(line_no, "expected 'element NAME COUNT'".into()));
    };
    let count = count
        .parse::<u64>()
        .map_err(|_| err(line_no, format!("element count {count:?} is not a number")))?;
    Ok(Element {
        name: (*name).to_owned(),
        count,
        props: Vec::new(),
    })
}

/// A `property TYPE NAME` or `property list CTYPE TYPE NAME` line.
fn parse_property(words: &[&str], line_no: usize) -> Result<Property, PlyError> {
    let err = header_err;
    Ok(match words {
        ["property", "list", ct, it, name] => Property {
            name: (*name).to_owned(),
            list: Some(
                Scalar::parse(ct)
                    .ok_or_else(|| err(line_no, format!("unknown list count type {ct:?}")))?,
            ),
            ty: Scalar::parse(it).ok_or_else(|| err(line_no, format!("unknown type {it:?}")))?,
        },
        ["property", ty, name] => Property {
            name: (*name).to_owned(),
            list: None,
            ty: Scalar::parse(ty).ok_or_else(|| err(line_no, format!("unknown type {ty:?}")))?,
        },
        _ => {
            return Err(err(
                line_no,
                "expected 'property TYPE NAME' or 'property list CTYPE TYPE NAME'".into(),
            ));
        }
    })
}
