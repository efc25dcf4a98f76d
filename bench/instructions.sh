#!/usr/bin/env bash
# Instructions per sample of a candela binary on a scene, by callgrind: the render at 64 x 64,
# max_depth 8 (Mitsuba's convention), one thread, 16 frames minus 8 frames (the difference drops
# loading, the tree's build and the output), divided by 8 x 64 x 64 samples. Instruction counts
# do not drift with the machine's load as times do; OMP_WAIT_POLICY=passive keeps OpenMP's
# spinning out of the count. Needs valgrind.
#
# Usage: bash bench/instructions.sh BINARY SCENE.xml
#   The scene must declare `res` (<default name="res" .../>), else its own size is rendered and
#   the figure is off by the ratio of the sizes.
# Example: CANDELA_STAGED=0 bash bench/instructions.sh build/bin/candela scenes/cornell-box/scene.xml
set -euo pipefail
if [ $# -ne 2 ]; then
  sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
bin=$1 scene=$2
grep -q '<default[^>]*name="res"' "$scene" || echo "note: $scene declares no res: its own size is rendered" >&2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
count() {
  OMP_WAIT_POLICY=passive valgrind --tool=callgrind --callgrind-out-file=/dev/null "$bin" "$scene" -D res=64 \
    -D max_depth=8 --frames "$1" --threads 1 --out "$out/img.exr" 2>&1 | sed -n 's/.*Collected : \([0-9]*\).*/\1/p'
}
a=$(count 16)
b=$(count 8)
echo "$scene: $(( (a - b) / (8 * 64 * 64) )) instructions per sample"
