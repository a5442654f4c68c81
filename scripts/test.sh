#!/usr/bin/env bash
# Set-up command 2: installs what is missing and runs the whole test suite on the default
# Vulkan device (lavapipe on a machine without a GPU), with validation layers on.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/deps.sh
# `cargo test` builds the engine only as the tests' rlib; the C hosts link its staticlib and
# cdylib, which only `cargo build` makes.
cargo build --release --workspace
cargo test --release --workspace "$@"
# The API documentation builds with every intra-doc link resolved.
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --workspace --quiet
