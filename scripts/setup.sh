#!/usr/bin/env bash
# Installs the Debian 12 packages candela needs. Idempotent: when everything is present it only
# queries dpkg and returns; it runs `apt-get update` only when something is missing.
# Usage: bash scripts/setup.sh [--with-embree] [--with-fuzz] [--with-mpi]
#   --with-fuzz: clang and libFuzzer for scripts/fuzz.sh; --with-mpi: Open MPI for distributed
#   rendering (docs/distributed.md; the build turns CANDELA_MPI on when it finds it)
set -euo pipefail
# Open Image Denoise (docs/denoising.md) is no Debian package: setup-oidn.sh takes it from the
# pyoidn wheel (with pip, python3-pip below) once the packages are in.
oidn() { bash "$(dirname "${BASH_SOURCE[0]}")/setup-oidn.sh"; }
pkgs=(
  cmake ninja-build g++ pkg-config
  libglfw3-dev libglm-dev libimgui-dev libtinyobjloader-dev libstb-dev
  libosmesa6-dev libgl-dev libpugixml-dev libcli11-dev libtinyexr-dev
  libgtest-dev libgmock-dev libbenchmark-dev zlib1g-dev libjpeg62-turbo-dev libhwy-dev
  xvfb xauth python3-pip
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
  oidn
  exit 0
fi
echo "setup.sh: installing ${missing[*]}" >&2
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"

# On a machine that is still installing its updates, another apt-get or dpkg holds the package
# locks (/var/lib/dpkg/lock-frontend, /var/lib/dpkg/lock, /var/lib/apt/lists/lock,
# /var/cache/apt/archives/lock) and apt-get fails at once with "Could not get lock". apt's own
# DPkg::Lock::Timeout does not help: apt-get update ignores it (the lists lock; apt 2.6), and with
# -qq apt says nothing while it waits. So each apt-get is retried every 5 s while it fails for a
# lock, with a message, for at most CANDELA_APT_LOCK_WAIT seconds in all (default 600). A failed
# attempt changed nothing: apt takes its locks before it does anything.
lock_wait=${CANDELA_APT_LOCK_WAIT:-600}
lock_deadline=$((SECONDS + lock_wait))
apt_get() {
  local err waiting=""
  err=$(mktemp)
  while :; do
    if DEBIAN_FRONTEND=noninteractive $SUDO apt-get "$@" 2>"$err"; then
      cat "$err" >&2
      break
    fi
    if ! grep -q "Could not get lock\|Unable to lock\|Unable to acquire the dpkg frontend lock" "$err"; then
      cat "$err" >&2
      rm -f "$err"
      return 1
    fi
    if [ "$SECONDS" -ge "$lock_deadline" ]; then
      cat "$err" >&2
      echo "setup.sh: another package manager still holds the lock after ${lock_wait} s; run this again when it is done" >&2
      rm -f "$err"
      return 1
    fi
    if [ -z "$waiting" ]; then
      echo "setup.sh: waiting (at most ${lock_wait} s) for another package manager: $(grep -m1 "Could not get lock\|Unable to" "$err" | sed 's/^E: //')" >&2
      waiting=1
    fi
    sleep 5
  done
  rm -f "$err"
  [ -z "$waiting" ] || echo "setup.sh: the lock is free; going on" >&2
}
apt_get update -qq
apt_get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
oidn
