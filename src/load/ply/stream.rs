//! Binary PLY read in chunks of rows ([`PlyRows`]), for work on scenes that do not fit in
//! memory (`convert … tileset.json --scratch-dir`): the header is parsed once, then each
//! chunk's rows are read from the file and decoded exactly as [`read`](super::read) decodes a
//! whole file (the same layout, conversions and numeric hygiene). ASCII and PlayCanvas
//! compressed PLY are not streamed (their rows are not fixed-size or depend on chunk records).

use super::header::{Encoding, Header, parse_header};
use super::{Layout, PlyError, decode_binary, layout};
use crate::cloud::SplatCloud;
use crate::load::{Finding, LoadOptions};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

/// The most header bytes read looking for `end_header`.
const MAX_HEADER: usize = 1 << 20;

/// A chunk's rows take at most this many bytes (fewer rows when they are wide).
const MAX_CHUNK_BYTES: u64 = 64 << 20;

/// Why a PLY could not be read in chunks ([`PlyRows`]); each names the file.
#[derive(Debug, thiserror::Error)]
pub enum StreamError {
    /// The file could not be opened or read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// Its header or rows break the format (the PLY loader's error).
    #[error("{}: {source}", path.display())]
    Ply {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        source: PlyError,
    },
    /// A PLY that is not read in chunks (ASCII, PlayCanvas compressed, list properties before
    /// the `vertex` element).
    #[error("{}: {why}", path.display())]
    NotStreamable {
        /// The file.
        path: PathBuf,
        /// Why, and what to do.
        why: String,
    },
    /// With `strict`, a row with unusable values.
    #[error("{}: vertex row {row}: {why}", path.display())]
    BadRow {
        /// The file.
        path: PathBuf,
        /// The row's index in the file.
        row: u64,
        /// What is wrong with it.
        why: String,
    },
}

impl From<StreamError> for String {
    fn from(e: StreamError) -> String {
        e.to_string()
    }
}

/// A binary PLY's `vertex` rows, read a chunk at a time.
pub struct PlyRows {
    path: PathBuf,
    file: File,
    header: Header,
    vertex: usize,
    layout: Layout,
    be: bool,
    /// Byte offset of the first vertex row.
    start: u64,
    next: u64,
    strict: bool,
    /// What the rows read so far showed (opacity logits at ±inf, dropped rows), one line
    /// each, with the row index in the file.
    pub findings: Vec<Finding>,
}

impl PlyRows {
    /// Opens `path` and parses its header. Errors: not a PLY, ASCII or compressed PLY, no
    /// `vertex` element, elements before it that are not fixed-size, or a file shorter than
    /// its header says.
    pub fn open(path: &Path, opts: &LoadOptions) -> Result<Self, StreamError> {
        let io = |source| StreamError::Io {
            path: path.to_owned(),
            source,
        };
        let ply = |source| StreamError::Ply {
            path: path.to_owned(),
            source,
        };
        let not = |why: &str| StreamError::NotStreamable {
            path: path.to_owned(),
            why: why.to_owned(),
        };
        let mut file = File::open(path).map_err(io)?;
        let mut head = Vec::new();
        (&mut file)
            .take(MAX_HEADER as u64)
            .read_to_end(&mut head)
            .map_err(io)?;
        let header = parse_header(&head).map_err(ply)?;
        if header.encoding == Encoding::Ascii {
            return Err(not(
                "ASCII PLY is not read in chunks; convert it to binary first",
            ));
        }
        let vertex = header
            .elements
            .iter()
            .position(|e| e.name == "vertex")
            .ok_or_else(|| ply(PlyError::NoVertexElement))?;
        let v = &header.elements[vertex];
        if super::compressed::is_compressed(v) {
            return Err(not("PlayCanvas compressed PLY is not read in chunks"));
        }
        let layout = layout(v).map_err(ply)?;
        let be = header.encoding == Encoding::Be;
        let mut before = 0u64;
        for e in &header.elements[..vertex] {
            if e.props.iter().any(|p| p.list.is_some()) {
                return Err(not(&format!(
                    "element '{}' before 'vertex' has list properties",
                    e.name
                )));
            }
            let row: u64 = e.props.iter().map(|p| p.ty.size() as u64).sum();
            before = before.saturating_add(row.saturating_mul(e.count));
        }
        let start = (header.body as u64).saturating_add(before);
        let len = file.metadata().map_err(io)?.len();
        let needed = v.count.saturating_mul(layout.stride as u64);
        if len.saturating_sub(start) < needed || (v.count > 0 && layout.stride == 0) {
            return Err(ply(PlyError::Truncated {
                element: "vertex".into(),
                count: v.count,
                needed,
                available: len.saturating_sub(start),
            }));
        }
        Ok(PlyRows {
            path: path.to_owned(),
            file,
            header,
            vertex,
            layout,
            be,
            start,
            next: 0,
            strict: opts.strict,
            findings: Vec::new(),
        })
    }

    /// Rows in the file.
    pub fn len(&self) -> u64 {
        self.header.elements[self.vertex].count
    }

    /// Whether the file has no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The SH degree of every row.
    pub fn sh_degree(&self) -> u8 {
        self.layout.sh_degree
    }

    /// Starts again from the first row.
    pub fn rewind(&mut self) {
        self.seek(0);
    }

    /// Goes on from row `row` (clamped to the rows there are), forgetting the findings.
    pub fn seek(&mut self, row: u64) {
        self.next = row.min(self.len());
        self.findings.clear();
    }

    /// The row the next chunk starts at.
    pub fn position(&self) -> u64 {
        self.next
    }

    /// The next at most `rows` rows (`None` after the last; fewer when `rows` of them would
    /// take more than 64 MiB). Unusable rows are dropped (and
    /// counted in [`Self::findings`]) or, with `strict`, an error naming the row.
    pub fn next_chunk(&mut self, rows: usize) -> Option<Result<SplatCloud, StreamError>> {
        let left = self.len() - self.next;
        if left == 0 {
            return None;
        }
        // At most MAX_CHUNK_BYTES a chunk, however wide the rows.
        let fit = (MAX_CHUNK_BYTES / (self.layout.stride as u64).max(1)).max(1);
        let n = left.min(rows.max(1) as u64).min(fit);
        Some(self.read(n))
    }

    fn read(&mut self, n: u64) -> Result<SplatCloud, StreamError> {
        let path = &self.path;
        let io = |source| StreamError::Io {
            path: path.clone(),
            source,
        };
        let stride = self.layout.stride as u64;
        let first = self.next;
        self.file
            .seek(SeekFrom::Start(self.start + first * stride))
            .map_err(io)?;
        let mut bytes = vec![0u8; (n * stride) as usize];
        self.file.read_exact(&mut bytes).map_err(io)?;
        let props = &self.header.elements[self.vertex].props;
        let (mut cloud, notes, bad) =
            decode_binary(&self.layout, props, &bytes, self.be).map_err(|source| {
                StreamError::Ply {
                    path: path.clone(),
                    source,
                }
            })?;
        self.next += n;
        let at = |i: usize| first + i as u64;
        if let Some(i) = notes.first_inf {
            self.findings.push(
                Finding::warning(
                    "vertex.opacity",
                    format!(
                        "{} opacity logits are ±inf (read as opacity 1 or 0)",
                        notes.inf_opacity
                    ),
                )
                .at(at(i)),
            );
        }
        if let Some(&i) = bad.rows.first() {
            if self.strict {
                let why = bad.first.as_ref().map_or(String::new(), |e| e.to_string());
                return Err(StreamError::BadRow {
                    path: self.path.clone(),
                    row: at(i),
                    why,
                });
            }
            self.findings.push(
                Finding::warning(
                    "vertex",
                    format!("{} rows with unusable values were dropped", bad.rows.len()),
                )
                .at(at(i)),
            );
            crate::load::hygiene::drop_splats(&mut cloud, &bad.rows);
        }
        Ok(cloud)
    }
}
