#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test under ctest.
# Usage: bash scripts/test.sh [--sanitize]   (--sanitize: the ASan+UBSan build in build-asan/)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/setup.sh
dir=$(bash scripts/build.sh "$@" | tail -n 1)
cd "$dir"
ctest --output-on-failure -j"$(nproc)" --timeout 600
