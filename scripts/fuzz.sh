#!/usr/bin/env bash
# Fuzzes the scene loaders with libFuzzer (clang-14, ASan + UBSan) for a bounded time; not part of
# ctest. Builds tests/fuzz/ into build-fuzz/, then runs each target for SECONDS (default 300) on a
# working corpus in build-fuzz/corpus/<target> seeded from tests/fuzz/corpus/. Crashing inputs land
# in build-fuzz/artifacts/<target>/; the script prints them and exits 1 if there are any.
# Usage: bash scripts/fuzz.sh [SECONDS] [TARGET...]      (targets: fuzz_xml fuzz_obj fuzz_ply fuzz_serialized fuzz_image fuzz_curve fuzz_vol)
# Replay one input: build-fuzz/fuzz_xml FILE
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
secs=${1:-300}
shift || true
targets=("$@")
[ "${#targets[@]}" -eq 0 ] && targets=(fuzz_xml fuzz_obj fuzz_ply fuzz_serialized fuzz_image fuzz_curve fuzz_vol)
bash scripts/setup.sh --with-fuzz

if [ ! -f build-fuzz/build.ninja ]; then
  cmake -S tests/fuzz -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 >/dev/null
fi
cmake --build build-fuzz -j"$(nproc)" --target "${targets[@]}" >&2

# Leaks are findings too; a scene that needs more than 2 GB, or one input over 10 s, is a finding.
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:symbolize=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
status=0
for t in "${targets[@]}"; do
  kind=${t#fuzz_}
  corpus=build-fuzz/corpus/$t
  artifacts=build-fuzz/artifacts/$t
  mkdir -p "$corpus" "$artifacts"
  # Fork mode with -ignore_*: a finding is saved and fuzzing goes on, so one known bug does not
  # end the run. /usr/bin/time measures the CPU time of the fuzzer and its jobs.
  set +e
  /usr/bin/time -f '%e %U %S' -o "build-fuzz/$t.time" \
    build-fuzz/$t "$corpus" "tests/fuzz/corpus/$kind" -dict="tests/fuzz/$kind.dict" \
    -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -max_len=8192 \
    -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -artifact_prefix="$artifacts/" >"build-fuzz/$t.log" 2>&1
  rc=$?
  set -e
  read -r wall user sys <"build-fuzz/$t.time" || true
  last=$(grep -E '^#[0-9]+' "build-fuzz/$t.log" | tail -n 1 || true)
  cpu=$(awk -v u="${user:-0}" -v s="${sys:-0}" 'BEGIN { printf "%.1f", (u + s) / 60 }')
  echo "fuzz.sh: $t: ${wall:-?} s wall, $cpu CPU-minutes, exit $rc; last status: $last"
  if [ "$rc" -ne 0 ] || [ -n "$(ls -A "$artifacts")" ]; then
    status=1
    grep -E 'ERROR|SUMMARY|==[0-9]+==' "build-fuzz/$t.log" | head -n 20 || true
    ls -1 "$artifacts"/* 2>/dev/null | sed 's/^/fuzz.sh:   finding: /'
  fi
done
exit $status
