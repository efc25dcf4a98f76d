#!/usr/bin/env bash
# Configures and builds candela. Usage: bash scripts/build.sh [--sanitize] [--embree] [--debug] [--mpi] [--target T]...
# --target builds only the named targets (scripts/run.sh builds the program alone); default: all.
# Release build in build/ (ASan+UBSan build in build-asan/ with --sanitize). MPI (CANDELA_MPI) is on
# when Open MPI is installed; --mpi insists on it (an error without it), and the sanitizer and
# Debug builds leave it off (Open MPI's own leaks are not ours; docs/distributed.md). The sanitizer
# build leaves out the benchmarks (no test runs them; instrumented they took a fifth of its build).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
dir=build
type=Release
extra=()
targets=()
while [ $# -gt 0 ]; do
  a=$1; shift
  case "$a" in
    --target) targets+=(--target "${1:?build.sh: --target needs a name}"); shift ;;
    --sanitize) dir=build-asan; type=RelWithDebInfo; extra+=(-DCANDELA_SANITIZE=ON -DCANDELA_MPI=OFF -DCANDELA_BENCH=OFF) ;;
    --embree) extra+=(-DCANDELA_EMBREE=ON) ;;
    --debug) dir=build-debug; type=Debug; extra+=(-DCANDELA_MPI=OFF -DCANDELA_BENCH=OFF) ;;
    --mpi) extra+=(-DCANDELA_MPI=ON) ;;
    *) echo "build.sh: unknown option '$a'" >&2; exit 2 ;;
  esac
done
# CANDELA_CCACHE=1: compile through ccache (developers' worktrees and clones share objects: no
# object depends on the checkout's path; set CCACHE_BASEDIR to the folder that holds them).
if [ "${CANDELA_CCACHE:-0}" = 1 ] && command -v ccache >/dev/null; then
  extra+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
if [ ! -f "$dir/build.ninja" ]; then
  cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE="$type" "${extra[@]}" >/dev/null
elif [ "${#extra[@]}" -gt 0 ]; then
  cmake "$dir" "${extra[@]}" >/dev/null
fi
cmake --build "$dir" -j"$(nproc)" "${targets[@]}" >&2
echo "$dir"
