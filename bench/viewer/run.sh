#!/bin/sh
# Viewer responsiveness benchmark under Xvfb (Mesa llvmpipe). Usage:
#   bench/viewer/run.sh [BUILD_DIR] [candela-bench-viewer options...]
# e.g. bench/viewer/run.sh build --size 512 --threads 2 --duration 20
set -e
build=${1:-build}
[ $# -gt 0 ] && shift
exec xvfb-run -a -s "-screen 0 1280x800x24" "$build/bin/candela-bench-viewer" "$@"
