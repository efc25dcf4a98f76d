#!/usr/bin/env bash
# Installs Intel Open Image Denoise 2.5.1 for candela's --denoise and the viewer's denoised view
# (docs/denoising.md). Debian 12 has no package of it; the `pyoidn` wheel on PyPI carries the
# library (its CPU device, TBB and the trained weights). This takes the wheel with pip (a wheel is
# a zip: no Python package is installed) and keeps the few files candela loads under
#   ${XDG_CACHE_HOME:-$HOME/.cache}/candela/oidn-2.5.1/lib
# which is where candela looks (src/denoise/denoiser.h). Idempotent: a second run only checks that
# the library is there. Never fatal: without the library candela only loses denoising, and says so.
# Called by scripts/setup.sh.
set -uo pipefail
ver=2.5.1
wheel_ver=2.5.1.0
dest="${XDG_CACHE_HOME:-$HOME/.cache}/candela/oidn-$ver"
[ -e "$dest/lib/libOpenImageDenoise.so.2" ] && exit 0
warn() { echo "setup-oidn.sh: $*; denoising will be unavailable" >&2; exit 0; }
command -v python3 >/dev/null || warn "python3 is missing"
python3 -m pip --version >/dev/null 2>&1 || warn "pip is missing (scripts/setup.sh installs python3-pip)"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
echo "setup-oidn.sh: fetching Open Image Denoise $ver (the pyoidn $wheel_ver wheel, ~90 MB)" >&2
python3 -m pip download --quiet --disable-pip-version-check --no-deps --only-binary=:all: \
  --dest "$tmp" "pyoidn==$wheel_ver" || warn "pip could not download pyoidn==$wheel_ver"
whl="$(ls "$tmp"/pyoidn-*.whl 2>/dev/null | head -n 1)"
[ -n "$whl" ] || warn "no pyoidn wheel for this machine"
# Only the CPU device and what it needs (the GPU devices and SYCL runtime are most of the wheel).
python3 - "$whl" "$tmp/new" <<'PY' || warn "cannot unpack $whl"
import os, sys, zipfile
whl, out = sys.argv[1], sys.argv[2]
keep = ("libOpenImageDenoise.so.2.5.1", "libOpenImageDenoise_core.so.2.5.1",
        "libOpenImageDenoise_device_cpu.so.2.5.1", "libtbb.so.12.19")
os.makedirs(os.path.join(out, "lib"))
with zipfile.ZipFile(whl) as z:
    names = z.namelist()
    for k in keep:
        src = [n for n in names if n.endswith("/oidn/lib/" + k)]
        if not src:
            sys.exit("missing " + k)
        with z.open(src[0]) as f, open(os.path.join(out, "lib", k), "wb") as g:
            g.write(f.read())
        os.chmod(os.path.join(out, "lib", k), 0o755)
    lic = [n for n in names if n.endswith("LICENSE")]
    if lic:
        with z.open(lic[0]) as f, open(os.path.join(out, "LICENSE"), "wb") as g:
            g.write(f.read())
PY
ln -s libOpenImageDenoise.so.2.5.1 "$tmp/new/lib/libOpenImageDenoise.so.2"
ln -s libtbb.so.12.19 "$tmp/new/lib/libtbb.so.12"
mkdir -p "$(dirname "$dest")"
rm -rf "$dest"
mv "$tmp/new" "$dest" || warn "cannot move the library to $dest"
echo "setup-oidn.sh: Open Image Denoise $ver in $dest" >&2
