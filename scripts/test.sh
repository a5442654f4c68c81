#!/usr/bin/env bash
# Set-up command 2: installs what is missing and runs the whole test suite on the default
# Vulkan device (lavapipe on a machine without a GPU), with validation layers on.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/deps.sh
cargo test --release --workspace "$@"
