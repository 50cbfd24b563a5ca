//! GL benchmark.
fn main() {}
