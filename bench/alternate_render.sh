#!/usr/bin/env bash
# Two candela binaries (or one binary with two environments) rendering the same scene in turn,
# ROUNDS times: on a shared machine one run can be 10-30% slow for reasons outside the program, and
# alternating compares the two under the same conditions. Prints each side's Msamples/s per round,
# its best and its median, and whether the two last images are byte-identical.
#
# Usage: bash bench/alternate_render.sh A B SCENE [ROUNDS [THREADS]]
#   A, B: a candela binary, optionally preceded by NAME=VALUE environment settings in the same
#         word ('OMP_WAIT_POLICY=passive build/bin/candela').
#   The render: 256 x 256, 128 spp (one per pass), the XML's max_depth 8 (Mitsuba's convention:
#   7 scattering events in candela's), THREADS threads (default 2); ROUNDS defaults to 4.
# Example: bash bench/alternate_render.sh /tmp/candela-before build/bin/candela scenes/cornell-box/scene.xml 6
set -euo pipefail
if [ $# -lt 3 ]; then
  sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
a=$1 b=$2 scene=$3 rounds=${4:-4} threads=${5:-2}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
args=(-D res=256 -D width=256 -D height=256 -D spp=128 -D max_depth=8 --frames 128 --threads "$threads")
run() {  # run "ENV... BINARY" IMAGE: prints Msamples/s
  local words=($1)
  env "${words[@]}" "$scene" "${args[@]}" --out "$2" 2>&1 | tail -n 1 | sed -n 's/.* \([0-9.]*\) Msamples\/s.*/\1/p'
}
ra=() rb=()
for _ in $(seq "$rounds"); do
  ra+=("$(run "$a" "$out/a.exr")")
  rb+=("$(run "$b" "$out/b.exr")")
done
summary() {
  printf '%s\n' "$@" | sort -n | awk '{v[NR] = $1} END {m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2;
                                                   printf "best %s  median %.3f", v[NR], m}'
}
echo "A: ${ra[*]}   $(summary "${ra[@]}")   ($a)"
echo "B: ${rb[*]}   $(summary "${rb[@]}")   ($b)"
if cmp -s "$out/a.exr" "$out/b.exr"; then echo "images identical"; else echo "images differ"; fi
