#!/usr/bin/env bash
# Installs the Debian 12 packages candela needs. Idempotent: when everything is present it only
# queries dpkg and returns; it runs `apt-get update` only when something is missing.
# Usage: bash scripts/setup.sh [--with-embree] [--with-fuzz] [--with-mpi]
#   --with-fuzz: clang and libFuzzer for scripts/fuzz.sh; --with-mpi: Open MPI for distributed
#   rendering (docs/distributed.md; the build turns CANDELA_MPI on when it finds it)
set -euo pipefail
# Open Image Denoise (docs/denoising.md) is no Debian package: setup-oidn.sh fetches it once the
# packages are in, on every successful way out of this script.
trap 'rc=$?; [ "$rc" -eq 0 ] && bash "$(dirname "${BASH_SOURCE[0]}")/setup-oidn.sh"; exit "$rc"' EXIT
pkgs=(
  cmake ninja-build g++ pkg-config
  libglfw3-dev libglm-dev libimgui-dev libtinyobjloader-dev libstb-dev
  libosmesa6-dev libgl-dev libpugixml-dev libcli11-dev libtinyexr-dev
  libgtest-dev libgmock-dev libbenchmark-dev zlib1g-dev libjpeg62-turbo-dev libhwy-dev
  xvfb xauth
)
for a in "$@"; do
  case "$a" in
    --with-embree) pkgs+=(libembree-dev) ;;
    --with-fuzz) pkgs+=(clang-14 libclang-rt-14-dev) ;;
    --with-mpi) pkgs+=(libopenmpi-dev openmpi-bin) ;;
    *) echo "setup.sh: unknown option '$a'" >&2; exit 2 ;;
  esac
done
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -eq 0 ]; then
  exit 0
fi
echo "setup.sh: installing ${missing[*]}" >&2
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
