#!/usr/bin/env bash
# The project's test command (README): format check, clippy with warnings as errors, docs
# without broken links, and every test of every target and feature.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo fmt --all -- --check
cargo clippy --all-targets --all-features --locked -- -D warnings
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --all-features --locked
cargo test --all-targets --all-features --locked
