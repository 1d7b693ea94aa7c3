#!/usr/bin/env bash
# Sets up (packages), builds the default preset and runs every test. Ends with ctest's summary line.
# Usage: tools/test.sh [preset]     (default: "default"; "debug" is the ASan+UBSan build)
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-default}"
./tools/setup.sh
cmake --preset "$preset"
cmake --build --preset "$preset"
ctest --preset "$preset"
