#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs candela. With a display it opens the
# viewer on the given scene (default: the built-in Cornell box); without one it renders the
# default scene headless to out/candela.png, unless the arguments name an --out of their own.
# Extra arguments go to candela.
# Usage: bash scripts/run.sh [SCENE] [candela options]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/setup.sh
bash scripts/build.sh --target candela >/dev/null  # the program alone: the tests are test.sh's
if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then
  exec build/bin/candela "$@"
fi
for arg in "$@"; do
  case "$arg" in
    --out | --out=*) exec build/bin/candela "$@" ;;  # a second --out would be a usage error
  esac
done
mkdir -p out
echo "run.sh: no display: rendering headless to out/candela.png" >&2
exec build/bin/candela "$@" --out out/candela.png
