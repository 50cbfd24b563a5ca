//! `splatgl validate` (in progress).
