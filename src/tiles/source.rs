//! [`PlySource`]: a binary PLY read in chunks as a [`SplatSource`], each chunk cropped,
//! relabelled and turned as `convert` turns a whole cloud — the input of the bucketed build,
//! in one process ([`super::build_streamed`]) or spread over workers ([`super::steps`]).

use super::SplatSource;
use crate::cloud::SplatCloud;
use crate::convert::{self, ConvertOptions, OutputFormat};
use crate::cull::CropBox;
use crate::load::ply::{PlyRows, StreamError};
use crate::load::{Format, LoadOptions};
use glam::DMat3;
use std::path::Path;

/// Rows per chunk of a streamed read.
pub const READ_ROWS: usize = 1 << 20;

/// A binary PLY's rows `start..end`, read a chunk at a time and turned into the output's frame
/// (glTF's +Y up: a tileset's content).
pub struct PlySource {
    /// The rows (their findings: rows dropped, ±inf opacities).
    pub rows: PlyRows,
    options: ConvertOptions,
    crop: Option<CropBox>,
    /// The rotation into the output's frame: decided on the file's first chunk (as it would
    /// be on the whole cloud), or given ([`Self::with_range`]).
    pub rotation: Option<DMat3>,
    start: u64,
    end: u64,
    /// Splats dropped by the crop box in the current pass.
    pub dropped: u64,
}

impl PlySource {
    /// All rows of the binary PLY at `path`. Errors: [`PlyRows::open`]'s.
    pub fn open(
        path: &Path,
        load: &LoadOptions,
        options: ConvertOptions,
        crop: Option<CropBox>,
    ) -> Result<Self, StreamError> {
        let rows = PlyRows::open(path, load)?;
        let end = rows.len();
        Ok(PlySource {
            rows,
            options,
            crop,
            rotation: None,
            start: 0,
            end,
            dropped: 0,
        })
    }

    /// Only rows `start..end` (clamped to the file), turned by `rotation`.
    pub fn with_range(mut self, start: u64, end: u64, rotation: DMat3) -> Self {
        self.end = end.min(self.rows.len());
        self.start = start.min(self.end);
        self.rotation = Some(rotation);
        self
    }
}

impl SplatSource for PlySource {
    fn len(&self) -> u64 {
        self.end - self.start
    }
    fn sh_degree(&self) -> u8 {
        self.options
            .sh_degree
            .map_or(self.rows.sh_degree(), |d| d.min(self.rows.sh_degree()))
    }
    fn rewind(&mut self) -> Result<(), String> {
        self.rows.seek(self.start);
        self.dropped = 0;
        Ok(())
    }
    fn next_chunk(&mut self) -> Option<Result<SplatCloud, String>> {
        let left = self.end.saturating_sub(self.rows.position());
        if left == 0 {
            return None;
        }
        let c = match self.rows.next_chunk(READ_ROWS.min(left as usize))? {
            Ok(c) => c,
            Err(e) => return Some(Err(e.into())),
        };
        let n = c.len();
        let mut c = match self.crop.and_then(|b| b.apply(&c)) {
            Some(kept) => kept,
            None => c,
        };
        self.dropped += (n - c.len()) as u64;
        convert::relabel(&mut c, &self.options);
        let (o, format) = (&self.options, Format::Ply);
        let r = *self
            .rotation
            .get_or_insert_with(|| o.rotation_for(format, &c, OutputFormat::Glb));
        Some(convert::rotate(&c, r).map_err(Into::into))
    }
}
