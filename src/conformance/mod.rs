//! conformance (WIP)
