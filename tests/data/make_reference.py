#!/usr/bin/env python3
"""Makes a committed reference for the image tests: the mean of K independent Mitsuba 3 renders
of a scene and the variance of that mean per pixel and channel (from the spread of the K batch
means), both written as float32 EXR.

Usage (PY from ../shared/tools/setup-reference.sh):
  $PY tests/data/make_reference.py scenes/cornell-box/scene.xml --res 64 --batches 16 --spp 4096 \
      --out tests/data/cornell64
writes tests/data/cornell64_mean.exr and tests/data/cornell64_var.exr.

--integrator TYPE renders with another Mitsuba integrator than the scene's (e.g. ptracer): a copy of
the scene beside it (so that its relative paths still resolve) with the type of its <integrator>
replaced, its parameters (max_depth, rr_depth) kept; the copy is removed afterwards.
"""
import argparse
import os
import re
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
TOOLS = os.path.normpath(os.path.join(HERE, "..", "..", "..", "shared", "tools"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("--res", type=int, default=64, help="the scene's $res (0: not passed, for scenes sized by -D width=, height=)")
    ap.add_argument("--batches", type=int, default=16)
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--out", required=True)
    ap.add_argument("-D", dest="defines", action="append", default=[])
    ap.add_argument("--integrator", help="replace the type of the scene's <integrator> (e.g. ptracer)")
    a = ap.parse_args()

    scene = a.scene
    if a.integrator:
        with open(a.scene) as fh:
            text = fh.read()
        text, n = re.subn(r'<integrator\s+type="[^"]*"', '<integrator type="%s"' % a.integrator, text, count=1)
        if n != 1:
            raise SystemExit("%s: no <integrator type=...> to replace" % a.scene)
        head, tail = os.path.split(os.path.abspath(a.scene))
        scene = os.path.join(head, ".%s.%s.%d.xml" % (tail[:-4], a.integrator, os.getpid()))
        with open(scene, "w") as fh:
            fh.write(text)
    try:
        render_batches(a, scene)
    finally:
        if scene != a.scene:
            os.remove(scene)


def render_batches(a, scene):
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    imgs = []
    for k in range(a.batches):
        path = "%s_batch%d.exr" % (a.out, k)
        cmd = [sys.executable, os.path.join(TOOLS, "mitsuba_render.py"), scene, "--variant", a.variant,
               "--spp", str(a.spp), "--seed", str(k + 1), "--out", path] + (["-D", "res=%d" % a.res] if a.res else [])
        for d in a.defines:
            cmd += ["-D", d]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        imgs.append(np.array(mi.Bitmap(path), dtype=np.float64)[:, :, :3])
        os.remove(path)
        if os.path.exists(path[:-4] + ".json"):  # mitsuba_render.py writes its timing beside
            os.remove(path[:-4] + ".json")
    stack = np.stack(imgs)
    mean = stack.mean(axis=0)
    var_of_mean = stack.var(axis=0, ddof=1) / a.batches
    mi.Bitmap(mean.astype(np.float32)).write(a.out + "_mean.exr")
    mi.Bitmap(var_of_mean.astype(np.float32)).write(a.out + "_var.exr")
    print("wrote %s_mean.exr and %s_var.exr: %d batches x %d spp%s, mean RGB %s"
          % (a.out, a.out, a.batches, a.spp, " (%s)" % a.integrator if a.integrator else "",
             mean.reshape(-1, 3).mean(axis=0)))


if __name__ == "__main__":
    main()
