#!/usr/bin/env python3
"""Writes the small images of tests/data/textures and prints what Mitsuba 3's `bitmap` and
`checkerboard` textures return at chosen uv points, as the C++ table of tests/test_texture.cpp.

Usage (PY from ../shared/tools/setup-reference.sh):
  $PY tests/data/make_texture_reference.py > /tmp/table.txt
"""
import os

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")
HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "textures")

UVS = [(0.1, 0.2), (0.5, 0.5), (0.9, 0.85), (1.3, -0.2), (-0.45, 1.7), (2.05, 0.55), (0.0, 0.0), (0.999, 0.001)]


def lit(x, digits=9):
    """A C++ float literal."""
    t = "%.*g" % (digits, x)
    if "." not in t and "e" not in t and "n" not in t:
        t += ".0"
    return t + "f"


def write_images():
    os.makedirs(OUT, exist_ok=True)
    rgb = np.array([[[10, 200, 30], [250, 5, 128], [64, 64, 255]],
                    [[0, 0, 0], [255, 255, 255], [128, 32, 7]]], dtype=np.uint8)  # 3 wide, 2 high
    mi.Bitmap(rgb, pixel_format=mi.Bitmap.PixelFormat.RGB).write(os.path.join(OUT, "rgb3x2.png"))
    grey = np.array([[20, 220], [90, 160]], dtype=np.uint8)
    mi.Bitmap(grey, pixel_format=mi.Bitmap.PixelFormat.Y).write(os.path.join(OUT, "grey2x2.png"))


def main():
    write_images()
    print("// file, filter, wrap, raw, u, v, r, g, b  (Mitsuba %s, scalar_rgb)" % mi.__version__)
    for name in ["rgb3x2.png", "grey2x2.png"]:
        for filt in ["bilinear", "nearest"]:
            for wrap in ["repeat", "mirror", "clamp"]:
                for raw in [False, True]:
                    tex = mi.load_dict({"type": "bitmap", "filename": os.path.join(OUT, name),
                                        "filter_type": filt, "wrap_mode": wrap, "raw": raw})
                    for (u, v) in UVS:
                        si = mi.SurfaceInteraction3f()
                        si.uv = mi.Point2f(u, v)
                        c = tex.eval(si)
                        print('    {"%s", "%s", "%s", %s, %s, %s, %s, %s, %s},' %
                              (name, filt, wrap, "true" if raw else "false", lit(u, 6), lit(v, 6), lit(c[0]),
                               lit(c[1]), lit(c[2])))
    tex = mi.load_dict({"type": "checkerboard", "color0": {"type": "rgb", "value": [0.9, 0.1, 0.2]},
                        "color1": {"type": "rgb", "value": [0.05, 0.6, 0.3]},
                        "to_uv": mi.ScalarTransform4f().scale([4, 3, 1])})
    print("// checkerboard color0 (0.9, 0.1, 0.2), color1 (0.05, 0.6, 0.3), to_uv scale 4 3 1: u, v, r, g, b")
    for (u, v) in UVS:
        si = mi.SurfaceInteraction3f()
        si.uv = mi.Point2f(u, v)
        c = tex.eval(si)
        print("    {%s, %s, %s, %s, %s}," % (lit(u, 6), lit(v, 6), lit(c[0]), lit(c[1]), lit(c[2])))


if __name__ == "__main__":
    main()
