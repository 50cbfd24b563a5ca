#!/usr/bin/env bash
# The project's test command (README): format check, clippy with warnings as errors, and
# every test of every target and feature.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo fmt --all -- --check
cargo clippy --all-targets --all-features --locked -- -D warnings
cargo test --all-targets --all-features --locked
