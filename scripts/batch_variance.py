#!/usr/bin/env python3
"""Per-sample variance of an integrator from many independent batches (docs/bdpt.md, "The light
tracer's variance against Mitsuba's").

Renders K batches of N samples per pixel with seeds 1..K, either with candela (--candela BIN) or
with Mitsuba 3 (--mitsuba VARIANT: needs the mitsuba Python package, e.g. the venv of
../shared/tools/setup-reference.sh), and prints, per channel:
  * the whole-image mean and the per-sample variance of the whole-image mean (N x the variance of
    the K batch means), with its standard error from the batch means' kurtosis;
  * the per-sample variance of a pixel, averaged over the pixels (N x the mean over pixels of the
    variance of the K batch values), and its median over the pixels.
Heavy tails make a variance estimate from a few batches unreliable: the standard error printed is
what K batches resolve.

  python3 scripts/batch_variance.py scenes/veach-mis/scene.xml --candela build/candela \\
      --integrator ptracer --width 48 --height 32 --batches 256 --spp 64 -D max_depth=-1
  $PY scripts/batch_variance.py scenes/veach-mis/scene.xml --mitsuba scalar_rgb \\
      --integrator ptracer --width 48 --height 32 --batches 256 --spp 64 -D max_depth=-1

--save FILE.npz keeps the K batch images.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

import numpy as np


def read_exr(path):
    """An EXR's RGB as float64 (through Mitsuba's Bitmap when it is there, else imageio)."""
    try:
        import mitsuba as mi
        if not mi.variant():
            mi.set_variant("scalar_rgb")
        return np.array(mi.Bitmap(path), dtype=np.float64)[:, :, :3]
    except ImportError:
        import imageio.v3 as iio
        return np.asarray(iio.imread(path), dtype=np.float64)[:, :, :3]


def candela_batches(a):
    out = []
    with tempfile.TemporaryDirectory() as d:
        for k in range(1, a.batches + 1):
            path = os.path.join(d, "b.exr")
            cmd = [a.candela, a.scene, "--width", str(a.width), "--height", str(a.height), "--frames", str(a.spp),
                   "--seed", str(k), "--quiet", "--out", path]
            if a.integrator:
                cmd += ["--integrator", a.integrator]
            if a.threads:
                cmd += ["--threads", str(a.threads)]
            for dfn in a.defines:
                cmd += ["-D", dfn]
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
            out.append(read_exr(path))
    return np.stack(out)


def mitsuba_batches(a):
    import mitsuba as mi
    mi.set_variant(a.mitsuba)
    scene_path = a.scene
    tmp = None
    if a.integrator:
        with open(a.scene) as fh:
            text = fh.read()
        text, n = re.subn(r'<integrator\s+type="[^"]*"', '<integrator type="%s"' % a.integrator, text, count=1)
        if n != 1:
            raise SystemExit("%s: no <integrator type=...> to replace" % a.scene)
        head, tail = os.path.split(os.path.abspath(a.scene))
        tmp = os.path.join(head, ".%s.%s.%d.xml" % (tail[:-4], a.integrator, os.getpid()))
        with open(tmp, "w") as fh:
            fh.write(text)
        scene_path = tmp
    try:
        params = {"width": a.width, "height": a.height, "spp": a.spp}
        for dfn in a.defines:
            k, v = dfn.split("=", 1)
            params[k] = int(v) if re.fullmatch(r"-?\d+", v) else v
        scene = mi.load_file(scene_path, **params)
    finally:
        if tmp:
            os.remove(tmp)
    out = []
    for k in range(1, a.batches + 1):
        img = mi.render(scene, seed=k, spp=a.spp)
        out.append(np.array(img, dtype=np.float64)[:, :, :3])
    return np.stack(out)


def report(stack, spp, label):
    K = stack.shape[0]
    means = stack.reshape(K, -1, 3).mean(axis=1)  # K x 3: the whole-image mean of each batch
    m = means.mean(axis=0)
    v = means.var(axis=0, ddof=1)
    c = means - m
    kurt = (c ** 4).mean(axis=0) / np.maximum((c ** 2).mean(axis=0) ** 2, 1e-300)
    v_se = v * np.sqrt(np.maximum(kurt - 1.0, 0.0) / K)
    pix_var = stack.var(axis=0, ddof=1)  # H x W x 3
    print("%s: %d batches x %d spp" % (label, K, spp))
    for ch, name in enumerate("RGB"):
        print("  %s  image mean %.5g  per-sample var of the image mean %.4g +- %.2g (kurtosis %.1f)  "
              "per-sample pixel var: mean %.4g, median %.4g"
              % (name, m[ch], spp * v[ch], spp * v_se[ch], kurt[ch], spp * pix_var[:, :, ch].mean(),
                 spp * np.median(pix_var[:, :, ch])))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--candela", help="the candela binary")
    g.add_argument("--mitsuba", help="a Mitsuba 3 variant (scalar_rgb, llvm_ad_rgb)")
    ap.add_argument("--integrator")
    ap.add_argument("--width", type=int, default=48)
    ap.add_argument("--height", type=int, default=32)
    ap.add_argument("--batches", type=int, default=256)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--threads", type=int, default=0, help="candela --threads (0: its default)")
    ap.add_argument("-D", dest="defines", action="append", default=[])
    ap.add_argument("--save")
    a = ap.parse_args()
    stack = candela_batches(a) if a.candela else mitsuba_batches(a)
    if a.save:
        np.savez_compressed(a.save, stack=stack)
    report(stack, a.spp, "candela" if a.candela else "mitsuba " + a.mitsuba)


if __name__ == "__main__":
    sys.exit(main())
