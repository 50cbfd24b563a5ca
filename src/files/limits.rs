//! [`Limits`]: every resource bound of a load in one place, with documented defaults.
//!
//! Readers check a limit **before** allocating what it bounds (a header's splat count, a
//! buffer's byte length, a compressed stream's inflated size) and fail with
//! [`LimitExceeded`], which names the limit and the CLI flag that raises it.

use std::fmt;

/// Resource limits of one load (`LoadOptions::limits`). `splatgl info -v` prints them;
/// `--max-splats` and `--max-bytes` set the first two.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Most splats one load may produce (after merging every primitive and instance).
    /// Default [`Limits::DEFAULT_MAX_SPLATS`] = 2²⁵ (33,554,432; about 7.9 GB in memory at
    /// SH degree 3, three times the largest published scenes).
    pub max_splats: u64,
    /// Most bytes read from files into memory: the scene file, and its external buffers
    /// together (also the bound of a `cameras.json` read). Bytes handed to `load_bytes` are the
    /// caller's and not counted. Default [`Limits::DEFAULT_MAX_BYTES`] = 4 GiB.
    pub max_bytes: u64,
    /// Most bytes a compressed format (gzip, zip) may inflate to, all streams of one load
    /// together. Default [`Limits::DEFAULT_MAX_DECOMPRESSED_BYTES`] = 4 GiB.
    pub max_decompressed_bytes: u64,
    /// Deepest nesting of JSON arrays and objects (glTF, `cameras.json`). Default
    /// [`Limits::DEFAULT_MAX_JSON_DEPTH`] = 64; `serde_json` stops at 128 whatever this says.
    pub max_json_depth: u32,
    /// Most JSON values one document may hold (objects, arrays, strings — keys included —,
    /// numbers and literals), counted before it is parsed: parsing costs up to ~450 bytes per
    /// value (a glTF node), so this bounds the parse's memory whatever the file's size.
    /// Default [`Limits::DEFAULT_MAX_JSON_VALUES`] = 2²⁰ (1,048,576; real glTF, tileset and
    /// `cameras.json` files hold thousands); `--max-json-values` raises it.
    pub max_json_values: u64,
    /// glTF decode budget, fixed part: f32 values every document may decode or instantiate.
    /// Default [`Limits::DEFAULT_DECODE_BUDGET_VALUES`] = 16 Mi (64 MiB).
    pub decode_budget_values: u64,
    /// glTF decode budget, proportional part: values allowed per input byte (file and
    /// external buffers). Default [`Limits::DEFAULT_DECODE_VALUES_PER_BYTE`] = 4.
    pub decode_values_per_byte: u64,
}

impl Limits {
    /// Default of [`Limits::max_splats`].
    pub const DEFAULT_MAX_SPLATS: u64 = 1 << 25;
    /// Default of [`Limits::max_bytes`].
    pub const DEFAULT_MAX_BYTES: u64 = 4 << 30;
    /// Default of [`Limits::max_decompressed_bytes`].
    pub const DEFAULT_MAX_DECOMPRESSED_BYTES: u64 = 4 << 30;
    /// Default of [`Limits::max_json_depth`].
    pub const DEFAULT_MAX_JSON_DEPTH: u32 = 64;
    /// Default of [`Limits::max_json_values`].
    pub const DEFAULT_MAX_JSON_VALUES: u64 = 1 << 20;
    /// Default of [`Limits::decode_budget_values`].
    pub const DEFAULT_DECODE_BUDGET_VALUES: u64 = 16 << 20;
    /// Default of [`Limits::decode_values_per_byte`].
    pub const DEFAULT_DECODE_VALUES_PER_BYTE: u64 = 4;

    /// `n` splats are allowed; else an error naming `what` (e.g. `element 'vertex'`).
    pub fn check_splats(&self, n: u64, what: &str) -> Result<(), LimitExceeded> {
        check(n, self.max_splats, "max_splats", "splats", what)
    }

    /// `n` bytes (read so far, or about to be) are allowed by `max_bytes`.
    pub fn check_bytes(&self, n: u64, what: &str) -> Result<(), LimitExceeded> {
        check(n, self.max_bytes, "max_bytes", "bytes", what)
    }

    /// `n` inflated bytes (all streams so far together) are allowed by
    /// `max_decompressed_bytes`. Decompressors call it as they go, before growing a buffer.
    pub fn check_decompressed(&self, n: u64, what: &str) -> Result<(), LimitExceeded> {
        check(
            n,
            self.max_decompressed_bytes,
            "max_decompressed_bytes",
            "decompressed bytes",
            what,
        )
    }

    /// The glTF decode budget for `input` bytes of file and external buffers.
    pub fn decode_budget(&self, input: u64) -> u64 {
        self.decode_budget_values
            .saturating_add(self.decode_values_per_byte.saturating_mul(input))
    }

    /// Every limit as `(name, value)`, in declaration order (what `info -v` prints).
    pub fn entries(&self) -> [(&'static str, u64); 7] {
        [
            ("max_splats", self.max_splats),
            ("max_bytes", self.max_bytes),
            ("max_decompressed_bytes", self.max_decompressed_bytes),
            ("max_json_depth", self.max_json_depth as u64),
            ("max_json_values", self.max_json_values),
            ("decode_budget_values", self.decode_budget_values),
            ("decode_values_per_byte", self.decode_values_per_byte),
        ]
    }
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_splats: Self::DEFAULT_MAX_SPLATS,
            max_bytes: Self::DEFAULT_MAX_BYTES,
            max_decompressed_bytes: Self::DEFAULT_MAX_DECOMPRESSED_BYTES,
            max_json_depth: Self::DEFAULT_MAX_JSON_DEPTH,
            max_json_values: Self::DEFAULT_MAX_JSON_VALUES,
            decode_budget_values: Self::DEFAULT_DECODE_BUDGET_VALUES,
            decode_values_per_byte: Self::DEFAULT_DECODE_VALUES_PER_BYTE,
        }
    }
}

fn check(
    found: u64,
    limit: u64,
    name: &'static str,
    unit: &'static str,
    what: &str,
) -> Result<(), LimitExceeded> {
    if found <= limit {
        return Ok(());
    }
    Err(LimitExceeded {
        limit: name,
        value: limit,
        found,
        unit,
        what: what.to_owned(),
    })
}

/// A [`Limits`] bound was exceeded.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub struct LimitExceeded {
    /// The field of [`Limits`] (`"max_splats"`, …).
    pub limit: &'static str,
    /// Its value.
    pub value: u64,
    /// What the input needs.
    pub found: u64,
    /// Unit of both numbers (`"splats"`, `"bytes"`, …).
    pub unit: &'static str,
    /// What needs it (`element 'vertex'`, `buffers[0]`, …).
    pub what: String,
}

impl fmt::Display for LimitExceeded {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let flag = match self.limit {
            "max_splats" => " (raise with --max-splats)",
            "max_bytes" => " (raise with --max-bytes)",
            "max_json_values" => " (raise with --max-json-values)",
            _ => "",
        };
        write!(
            f,
            "{}: {} {} exceed limits.{} = {}{flag}",
            self.what, self.found, self.unit, self.limit, self.value
        )
    }
}

/// A JSON text past a limit, found before it is parsed ([`check_json`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum JsonShapeError {
    /// Arrays and objects nest deeper than the limit.
    #[error("JSON nests deeper than limits.max_json_depth = {max} (at byte {at})")]
    TooDeep {
        /// The limit.
        max: u32,
        /// The byte where it was passed.
        at: usize,
    },
    /// More values than the limit.
    #[error(
        "JSON holds more than limits.max_json_values = {max} values (at byte {at}; raise with \
         --max-json-values)"
    )]
    TooManyValues {
        /// The limit.
        max: u64,
        /// The byte where it was passed.
        at: usize,
    },
}

impl From<JsonShapeError> for String {
    fn from(e: JsonShapeError) -> String {
        e.to_string()
    }
}

/// Checks that the JSON text nests arrays and objects at most `max` deep (strings skipped),
/// before it is parsed.
pub fn check_json_depth(text: &[u8], max: u32) -> Result<(), JsonShapeError> {
    check_json_shape(text, max, u64::MAX)
}

/// Checks, before a JSON text is parsed, that it nests at most `limits.max_json_depth` deep
/// and holds at most `limits.max_json_values` values ([`Limits::max_json_values`] says what
/// counts). The error names the limit.
pub fn check_json(text: &[u8], limits: &Limits) -> Result<(), JsonShapeError> {
    check_json_shape(text, limits.max_json_depth, limits.max_json_values)
}

/// One pass over the text outside strings: depth and values counted as they open.
fn check_json_shape(text: &[u8], max_depth: u32, max_values: u64) -> Result<(), JsonShapeError> {
    let (mut depth, mut in_string, mut escaped) = (0u32, false, false);
    let (mut values, mut after_separator) = (0u64, true);
    for (i, &b) in text.iter().enumerate() {
        if in_string {
            match (escaped, b) {
                (true, _) => escaped = false,
                (false, b'\\') => escaped = true,
                (false, b'"') => in_string = false,
                _ => {}
            }
            continue;
        }
        // A value opens at a bracket, a quote, or a literal's first byte after `[`, `:`, `,`.
        let opens = match b {
            b'[' | b'{' | b'"' => true,
            b'-' | b'0'..=b'9' | b't' | b'f' | b'n' => after_separator,
            _ => false,
        };
        if opens {
            values += 1;
            if values > max_values {
                return Err(JsonShapeError::TooManyValues {
                    max: max_values,
                    at: i,
                });
            }
        }
        if !b.is_ascii_whitespace() {
            after_separator = matches!(b, b'[' | b':' | b',');
        }
        match b {
            b'"' => in_string = true,
            b'[' | b'{' => {
                depth += 1;
                if depth > max_depth {
                    return Err(JsonShapeError::TooDeep {
                        max: max_depth,
                        at: i,
                    });
                }
            }
            b']' | b'}' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_depth_counts_brackets_outside_strings() {
        assert!(check_json_depth(br#"{"a": [[1]], "b": "[[[[[[["}"#, 3).is_ok());
        let e = check_json_depth(br#"{"a": [[[1]]]}"#, 3)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("max_json_depth = 3") && e.contains("byte 8"),
            "{e}"
        );
        assert!(check_json_depth(br#"{"s": "\"[[[[", "t": 1}"#, 1).is_ok());
    }

    #[test]
    fn json_values_count_containers_strings_and_literals_once() {
        let limits = |n| Limits {
            max_json_values: n,
            ..Limits::default()
        };
        // {"a": [1, -2.5e3, true, null], "b": "x,1"}: the object, 2 keys, the array, 4
        // literals, 1 string = 9 values.
        let doc = br#"{"a": [1, -2.5e3, true, null], "b": "x,1"}"#;
        assert!(check_json(doc, &limits(9)).is_ok());
        let e = check_json(doc, &limits(8)).unwrap_err().to_string();
        assert!(
            e.contains("max_json_values = 8") && e.contains("--max-json-values"),
            "{e}"
        );
        // Empty objects in an array: one value each, and the array.
        let nodes = format!("[{}]", vec!["{}"; 100].join(","));
        assert!(check_json(nodes.as_bytes(), &limits(101)).is_ok());
        assert!(check_json(nodes.as_bytes(), &limits(100)).is_err());
    }

    #[test]
    fn limit_errors_name_the_limit_and_the_flag() {
        let l = Limits {
            max_splats: 10,
            ..Limits::default()
        };
        assert!(l.check_splats(10, "x").is_ok());
        let e = l
            .check_splats(11, "element 'vertex'")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "element 'vertex': 11 splats exceed limits.max_splats = 10 (raise with --max-splats)"
        );
    }
}
