//! The little of ZIP that a bundled `.sog` needs: the end-of-central-directory record, the
//! central directory, and members stored (method 0) or deflated (method 8), CRC-checked.
//! No zip64, no encryption, no multi-disk archives (each is a precise error).

use super::SogError;
use crate::load::codec;

const EOCD: u32 = 0x0605_4b50;
const CENTRAL: u32 = 0x0201_4b50;
const LOCAL: u32 = 0x0403_4b50;

/// One member of the archive.
#[derive(Debug, Clone)]
pub struct Entry {
    /// Name as stored.
    pub name: String,
    method: u16,
    flags: u16,
    crc: u32,
    packed: u64,
    size: u64,
    local: u64,
}

/// A parsed archive over borrowed bytes.
pub struct Archive<'a> {
    bytes: &'a [u8],
    /// Members in directory order.
    pub entries: Vec<Entry>,
}

fn bad(message: impl Into<String>) -> SogError {
    SogError::Zip(message.into())
}

impl<'a> Archive<'a> {
    /// Reads the central directory.
    pub fn new(bytes: &'a [u8]) -> Result<Self, SogError> {
        if bytes.len() < 22 {
            return Err(bad(format!("{} bytes, too short for a zip", bytes.len())));
        }
        // The EOCD record is the last 22 bytes plus a comment of up to 65535 bytes.
        let lowest = bytes.len().saturating_sub(22 + 0xffff);
        let eocd = (lowest..=bytes.len() - 22)
            .rev()
            .find(|&o| codec::u32_at(bytes, o) == EOCD)
            .ok_or_else(|| bad("no end-of-central-directory record"))?;
        let e = &bytes[eocd..];
        let (disk, cd_disk) = (codec::u16_at(e, 4), codec::u16_at(e, 6));
        let count = codec::u16_at(e, 10) as usize;
        let (cd_size, cd_off) = (codec::u32_at(e, 12) as u64, codec::u32_at(e, 16) as u64);
        if disk != 0 || cd_disk != 0 {
            return Err(bad("multi-disk archives are not supported"));
        }
        if count == 0xffff || cd_off == 0xffff_ffff || cd_size == 0xffff_ffff {
            return Err(bad("zip64 archives are not supported"));
        }
        if cd_off + cd_size > eocd as u64 {
            return Err(bad(format!(
                "central directory {cd_off}..{} runs past its end record at {eocd}",
                cd_off + cd_size
            )));
        }
        let mut entries = Vec::with_capacity(count.min(cd_size as usize / 46));
        let mut o = cd_off as usize;
        let end = (cd_off + cd_size) as usize;
        for k in 0..count {
            if o + 46 > end || codec::u32_at(bytes, o) != CENTRAL {
                return Err(bad(format!("central directory entry {k} is malformed")));
            }
            let c = &bytes[o..];
            let (n, x, m) = (
                codec::u16_at(c, 28) as usize,
                codec::u16_at(c, 30) as usize,
                codec::u16_at(c, 32) as usize,
            );
            if o + 46 + n > end {
                return Err(bad(format!(
                    "central directory entry {k}: name runs past it"
                )));
            }
            entries.push(Entry {
                name: String::from_utf8_lossy(&c[46..46 + n]).into_owned(),
                flags: codec::u16_at(c, 8),
                method: codec::u16_at(c, 10),
                crc: codec::u32_at(c, 16),
                packed: codec::u32_at(c, 20) as u64,
                size: codec::u32_at(c, 24) as u64,
                local: codec::u32_at(c, 42) as u64,
            });
            o += 46 + n + x + m;
        }
        Ok(Archive { bytes, entries })
    }

    /// Whether a member of this name exists.
    pub fn has(&self, name: &str) -> bool {
        self.entries.iter().any(|e| e.name == name)
    }

    /// Extracts `name`, charging its size to `budget` first.
    pub fn read(&self, name: &str, budget: &mut u64) -> Result<Vec<u8>, SogError> {
        let e = self
            .entries
            .iter()
            .find(|e| e.name == name)
            .ok_or_else(|| SogError::Missing {
                member: name.into(),
            })?;
        let fail = |message: String| SogError::Member {
            member: name.into(),
            message,
        };
        if e.flags & 1 != 0 {
            return Err(fail("encrypted members are not supported".into()));
        }
        if e.size > *budget {
            return Err(fail(format!(
                "unpacks to {} bytes, over the {} left of the budget ({})",
                e.size,
                budget,
                codec::BUDGET_RULE
            )));
        }
        let l = e.local as usize;
        if e.local + 30 > self.bytes.len() as u64 || codec::u32_at(self.bytes, l) != LOCAL {
            return Err(fail(format!("no local header at byte {}", e.local)));
        }
        let start = e.local
            + 30
            + codec::u16_at(self.bytes, l + 26) as u64
            + codec::u16_at(self.bytes, l + 28) as u64;
        if start + e.packed > self.bytes.len() as u64 {
            return Err(fail(format!(
                "data {start}..{} runs past the end of the archive ({} bytes)",
                start + e.packed,
                self.bytes.len()
            )));
        }
        let raw = &self.bytes[start as usize..(start + e.packed) as usize];
        let data = match e.method {
            0 if e.packed == e.size => raw.to_vec(),
            0 => {
                return Err(fail(format!(
                    "stored with {} bytes for {}",
                    e.packed, e.size
                )));
            }
            8 => codec::inflate_exact(raw, e.size).map_err(|err| fail(err.to_string()))?,
            m => return Err(fail(format!("compression method {m} (expected 0 or 8)"))),
        };
        let crc = crc32fast::hash(&data);
        if crc != e.crc {
            return Err(fail(format!(
                "CRC-32 {crc:08x}, the directory says {:08x}",
                e.crc
            )));
        }
        *budget -= e.size;
        Ok(data)
    }
}
