//! [`PlyError`]: what is wrong with a PLY file, with the element, property and index.

/// What is wrong with a PLY file.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PlyError {
    /// The header is malformed.
    #[error("header line {line}: {message}")]
    Header {
        /// 1-based header line.
        line: usize,
        /// What was expected.
        message: String,
    },
    /// No `vertex` element.
    #[error("no 'vertex' element in the header")]
    NoVertexElement,
    /// A required property is missing.
    #[error("element 'vertex': missing property '{property}' (required for a 3DGS PLY)")]
    MissingProperty {
        /// Its name.
        property: String,
    },
    /// A layout splatgl does not read yet.
    #[error("unsupported PLY layout: {0}")]
    Unsupported(String),
    /// `f_rest_*` count is not one of 0, 9, 24, 45.
    #[error(
        "element 'vertex': {count} f_rest_* properties; expected 0, 9, 24 or 45 (SH degree 0-3)"
    )]
    BadShCount {
        /// How many there are.
        count: usize,
    },
    /// The header claims more data than the file holds.
    #[error(
        "element '{element}': header claims {count} rows ({needed} bytes) but only {available} bytes follow"
    )]
    Truncated {
        /// Element name.
        element: String,
        /// Rows claimed.
        count: u64,
        /// Bytes needed (a lower bound for ASCII: two bytes per value).
        needed: u64,
        /// Bytes present.
        available: u64,
    },
    /// The data ends before all rows the header claims (rows of variable size, or ASCII).
    #[error("element '{element}': header claims {count} rows but the data ends after {rows_read}")]
    EndsEarly {
        /// Element name.
        element: String,
        /// Rows claimed.
        count: u64,
        /// Complete rows present.
        rows_read: u64,
    },
    /// A value that cannot be used.
    #[error("element 'vertex' index {index}: property '{property}': {message}")]
    Value {
        /// Row.
        index: usize,
        /// Property.
        property: String,
        /// What is wrong.
        message: String,
    },
    /// An ASCII body token that is not a number.
    #[error("ASCII body line {line}: {message}")]
    Ascii {
        /// 1-based line in the file.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A [`crate::load::Limits`] bound was exceeded.
    #[error(transparent)]
    Limit(#[from] crate::load::LimitExceeded),
}
