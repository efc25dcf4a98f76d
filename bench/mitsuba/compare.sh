#!/usr/bin/env bash
# candela against Mitsuba 3 on the same scene file, in one sitting: samples/s of candela and of
# Mitsuba's scalar_rgb and llvm_ad_rgb variants at the same resolution, spp, depth and thread count,
# and whether the images agree within Monte Carlo noise (../shared/tools/imgcmp.py).
#
# Usage: bash bench/mitsuba/compare.sh [SCENE.xml] [--res N] [--spp N] [--max-depth M] [--threads T]
#                                      [--rounds R] [--embree-build DIR]
#   SCENE defaults to scenes/cornell-box/scene.xml. Each -D goes only to a scene that declares it
#   (a published scene keeps its own size or depth when it has no parameter for them); --max-depth is MITSUBA's max_depth (path
#   segments; candela gets M - 1 through the XML); default 8, i.e. 7 scattering events.
#   --rounds R: candela and Mitsuba llvm rendered in turn R times (scalar once), each round's ratio
#   and their median printed: this machine is shared, and one run can be 10-30% slow for reasons
#   outside either program.
#   --embree-build DIR: a build configured with -DCANDELA_EMBREE=ON; its candela renders the scene
#   with the k-d tree and with Embree, in turn, and the ratio says how much of the distance to
#   Mitsuba is the accelerator's (bench/RESULTS.md, "A mesh scene").
# Output goes to out/bench-mitsuba/.
#
# A developer aid, optional: it needs Mitsuba 3 and the reference tools of ../shared/tools
# (setup-reference.sh, mitsuba_render.py, imgcmp.py), which live outside the repository. Nothing in
# the repository needs it: no test or build step calls it. The scenes it renders are the
# repository's (scenes/, bench/scenes/, assets/scenes-public/).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
scene=scenes/cornell-box/scene.xml
res=256 spp=256 depth=8 threads=2 embree_build= rounds=1
while [ $# -gt 0 ]; do
  case "$1" in
    --res) res=$2; shift 2 ;;
    --spp) spp=$2; shift 2 ;;
    --max-depth) depth=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --embree-build) embree_build=$2; shift 2 ;;
    --rounds) rounds=$2; shift 2 ;;
    -*) echo "compare.sh: unknown option $1" >&2; exit 2 ;;
    *) scene=$1; shift ;;
  esac
done
shared=../shared/tools
if [ ! -f "$shared/setup-reference.sh" ]; then
  echo "compare.sh: $shared (the Mitsuba 3 reference tools, a developer aid outside the repository) is absent" >&2
  exit 1
fi
eval "$(bash $shared/setup-reference.sh --no-apt | grep '^PY=')"
bash scripts/build.sh >/dev/null
out=out/bench-mitsuba
mkdir -p "$out"
# Only the parameters the scene declares (<default name=...>): Mitsuba refuses unused ones, and
# published scenes name their resolution res, width/height or resx/resy.
defs=()
for kv in "res=$res" "width=$res" "height=$res" "resx=$res" "resy=$res" "spp=$spp" "max_depth=$depth"; do
  grep -q "<default[^>]*name=\"${kv%%=*}\"" "$scene" && defs+=(-D "$kv")
done

echo "scene=$scene res=${res}x${res} spp=$spp mitsuba_max_depth=$depth threads=$threads machine=$(lscpu | sed -n 's/^Model name: *//p')"
# candela BINARY OUT.exr [ARGS...]: renders the scene, prints candela's summary line.
render() {
  local bin=$1 img=$2; shift 2
  "$bin" "$scene" "${defs[@]}" --frames "$spp" --threads "$threads" --out "$img" "$@" 2>&1 | tail -n 1
}
rate() { sed -n "s/.* \([0-9.]*\) $1\/s.*/\1/p"; }  # a rate from a summary line: Msamples or Mrays
ratio() { awk -v a="$1" -v b="$2" 'BEGIN{printf "%.2f", a / b}'; }
# mitsuba VARIANT: renders the scene, prints Mitsuba's samples/s in millions.
mitsuba() {
  "$PY" $shared/mitsuba_render.py "$scene" "${defs[@]}" --variant "$1" --spp "$spp" --threads "$threads" \
        --warmup --out "$out/mitsuba_$1.exr" > "$out/mitsuba_$1.log" 2>&1
  # The tool writes its timings next to the image as JSON (samples_per_s excludes load and warm-up).
  "$PY" -c 'import json, sys; print("%.3f" % (json.load(open(sys.argv[1]))["samples_per_s"] / 1e6))' \
        "$out/mitsuba_$1.json"
}
ratios=()
for round in $(seq "$rounds"); do
  tag=$([ "$rounds" -gt 1 ] && echo " (round $round)" || true)
  c_line=$(render build/bin/candela "$out/candela.exr")
  c_sps=$(echo "$c_line" | rate Msamples)
  echo "candela$tag:            $c_sps Msamples/s ($(echo "$c_line" | rate Mrays) Mrays/s)"
  for variant in scalar_rgb llvm_ad_rgb; do
    [ "$variant" = scalar_rgb ] && [ "$round" -gt 1 ] && continue
    sps=$(mitsuba $variant)
    echo "mitsuba $variant$tag: $sps Msamples/s   candela/mitsuba = $(ratio "$c_sps" "$sps")"
  done
  ratios+=("$(ratio "$c_sps" "$sps")")
done
if [ "$rounds" -gt 1 ]; then
  printf '%s\n' "${ratios[@]}" | sort -n | awk '{r[NR] = $1} END {
    m = NR % 2 ? r[(NR + 1) / 2] : (r[NR / 2] + r[NR / 2 + 1]) / 2
    printf "candela/mitsuba llvm_ad_rgb over %d alternating rounds: median %.2f (min %.2f, max %.2f)\n", NR, m, r[1], r[NR] }'
fi
if [ -n "$embree_build" ]; then
  # The same binary with each accelerator, alternated twice (the machine's noise is +-10%).
  for round in 1 2; do
    kd=$(render "$embree_build/bin/candela" "$out/candela_kdtree.exr" --accel kdtree | rate Msamples)
    em=$(render "$embree_build/bin/candela" "$out/candela_embree.exr" --accel embree | rate Msamples)
    echo "$embree_build candela, round $round: kdtree $kd, embree $em Msamples/s   kdtree/embree = $(ratio "$kd" "$em")"
  done
fi
echo "--- imgcmp candela vs mitsuba llvm_ad_rgb (same spp) ---"
"$PY" $shared/imgcmp.py "$out/candela.exr" "$out/mitsuba_llvm_ad_rgb.exr" --spp "$spp" --ref-spp "$spp" || true
