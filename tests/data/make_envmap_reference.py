#!/usr/bin/env python3
"""The environment-map test data (tests/test_envmap.cpp), made with Mitsuba 3.9.1:

  $PY tests/data/make_envmap_reference.py            # textures and the eval table (seconds)
  $PY tests/data/make_envmap_reference.py --images   # also the image references (a few minutes)

1. tests/data/textures/envmap_quadrants.exr (24 x 12): a distinct colour per quadrant of the
   image, a gradient along u, a bright 2 x 1 "sun" at pixels (17..18, 3) and a dim bottom row, so
   that any mirror, swap or offset of the lat-long orientation changes the answer.
   tests/data/textures/envmap_small.png (8 x 6, sRGB 8 bit): the same idea through the PNG decode.
   tests/data/textures/envmap_quadrants.hdr: the EXR written as RGBE (Radiance HDR).
2. tests/data/envmap_eval_mitsuba.txt: `case dx dy dz r g b` per line, Mitsuba's envmap eval
   (scalar_rgb, a SurfaceInteraction whose wi = -d) for directions d on the sphere (random, the
   axes, the poles and the seam), for the cases
     exr   the EXR, scale 1, no to_world
     rot   the EXR, scale 2.5, to_world = rotate(y, 70) * rotate(x, 30)
     png   the PNG, scale 1
     hdr   the RGBE file, scale 1
3. --images: tests/data/envmap_scene_{mean,var}.exr from tests/data/scenes/envmap.xml through
   make_reference.py (llvm_ad_rgb, 16 batches x 1024 spp, 32 x 32).
"""
import argparse
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def quadrant_image():
    w, h = 24, 12
    img = np.zeros((h, w, 3), dtype=np.float32)
    for y in range(h):
        for x in range(w):
            left, top = x < w // 2, y < h // 2
            c = {(True, True): (0.9, 0.15, 0.1), (False, True): (0.1, 0.8, 0.2),
                 (True, False): (0.1, 0.2, 0.9), (False, False): (0.8, 0.7, 0.1)}[(left, top)]
            g = 0.5 + x / (w - 1)  # gradient along u
            img[y, x] = np.array(c) * g
    img[3, 17:19] = (20.0, 18.0, 15.0)  # the sun
    img[h - 1, :] *= 0.2
    return img


def small_png(mi, path):
    w, h = 8, 6
    img = np.zeros((h, w, 3), dtype=np.uint8)
    for y in range(h):
        for x in range(w):
            img[y, x] = (30 * x + 10, 40 * y + 5, 255 - 25 * x - 10 * y)
    mi.Bitmap(img, mi.Bitmap.PixelFormat.RGB).write(path)


def directions(rng):
    d = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1),
         (0.001, 0.999999, 0.0), (0.0, -0.9999, 0.01), (1e-4, 0.3, -0.95), (-1e-4, 0.3, -0.95)]
    for _ in range(80):
        v = rng.normal(size=3)
        d.append(tuple(v))
    return [np.array(v, dtype=np.float64) / np.linalg.norm(v) for v in d]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--images", action="store_true")
    a = ap.parse_args()
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    tex = os.path.join(HERE, "textures")
    exr = os.path.join(tex, "envmap_quadrants.exr")
    png = os.path.join(tex, "envmap_small.png")
    hdr = os.path.join(tex, "envmap_quadrants.hdr")
    mi.Bitmap(quadrant_image()).write(exr)
    mi.Bitmap(quadrant_image()).write(hdr)
    small_png(mi, png)

    T = mi.ScalarTransform4f
    cases = {
        "exr": {"type": "envmap", "filename": exr},
        "rot": {"type": "envmap", "filename": exr, "scale": 2.5,
                "to_world": T().rotate([0, 1, 0], 70) @ T().rotate([1, 0, 0], 30)},
        "png": {"type": "envmap", "filename": png},
        "hdr": {"type": "envmap", "filename": hdr},
    }
    rng = np.random.default_rng(7)
    dirs = directions(rng)
    lines = []
    for name, desc in cases.items():
        e = mi.load_dict(desc)
        for d in dirs:
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(*(-d))
            v = e.eval(si)
            lines.append("%s %.9g %.9g %.9g %.9g %.9g %.9g" % (name, d[0], d[1], d[2], v[0], v[1], v[2]))
    with open(os.path.join(HERE, "envmap_eval_mitsuba.txt"), "w") as f:
        f.write("# made by make_envmap_reference.py with Mitsuba %s: case dx dy dz r g b\n" % mi.__version__)
        f.write("\n".join(lines) + "\n")
    print("wrote %d eval values" % len(lines))

    if a.images:
        subprocess.run([sys.executable, os.path.join(HERE, "make_reference.py"),
                        os.path.join(HERE, "scenes", "envmap.xml"), "--res", "32", "--batches", "16",
                        "--spp", "1024", "--out", os.path.join(HERE, "envmap_scene")], check=True)


if __name__ == "__main__":
    main()
