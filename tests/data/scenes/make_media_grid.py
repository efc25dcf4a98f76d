#!/usr/bin/env python3
"""Writes tests/data/scenes/media_grid.vol, the density grid of media_hetero.xml (tests/test_media.cpp):
a 12 x 10 x 8 one-channel float32 grid in Mitsuba's .vol format (docs/media.md), a smooth blob
with a denser off-centre lobe and empty corners, values in [0, 1.24]. Usage: python3 make_media_grid.py"""
import math
import os
import struct

X, Y, Z = 12, 10, 8
vals = []
for z in range(Z):
    for y in range(Y):
        for x in range(X):
            p = ((x + 0.5) / X - 0.5, (y + 0.5) / Y - 0.5, (z + 0.5) / Z - 0.5)
            r2 = p[0] ** 2 + p[1] ** 2 + p[2] ** 2
            lobe = (p[0] - 0.15) ** 2 + (p[1] + 0.1) ** 2 + p[2] ** 2
            vals.append(max(0.0, 1.0 - 3.0 * r2) + 0.6 * math.exp(-lobe / 0.01))
out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "media_grid.vol")
with open(out, "wb") as f:
    f.write(b"VOL" + bytes([3]) + struct.pack("<i", 1) + struct.pack("<4i", X, Y, Z, 1))
    f.write(struct.pack("<6f", 0, 0, 0, 1, 1, 1))
    f.write(struct.pack("<%df" % len(vals), *vals))
print("wrote", out, "max", max(vals))
