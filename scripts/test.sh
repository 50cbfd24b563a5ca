#!/usr/bin/env bash
# The project's test command (README): format check, clippy with warnings as errors, docs
# without broken links, an independent Python re-implementation of the reference's math, and
# every test of every target and feature.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo fmt --all -- --check
cargo fmt --manifest-path fuzz/Cargo.toml -- --check
cargo clippy --all-targets --all-features --locked -- -D warnings
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --all-features --locked
cargo build --locked --quiet
python3 scripts/xcheck_reference.py target/debug/splatgl
cargo test --all-targets --all-features --locked
