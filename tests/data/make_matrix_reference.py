#!/usr/bin/env python3
"""Makes the references of the integrator matrix (tests/test_matrix.cpp): each of the ten published
scenes of assets/scenes-public at a small size, rendered by Mitsuba 3 with its path tracer (the
reference of path, bdpt, pssmlt and mmlt), its direct integrator and its particle tracer, each as the
mean of K independent renders and the variance of that mean per pixel and channel (from the spread of
the K batch means), float32 EXR, in tests/data/matrix/SCENE_INTEGRATOR_{mean,var}.exr.

Usage (PY from ../shared/tools/setup-reference.sh; Mitsuba 3 is needed here only):
  $PY tests/data/make_matrix_reference.py [--only SCENE] [--batches 16] [--spp 1024]

Each scene is copied to a scratch folder with every <film>'s width and height rewritten to the
matrix's size (the table below; the aspect ratio kept, so that the camera's field of view is the
same); the scene's own filter, sampler and depth are kept. The integrator is built here with the
scene's max_depth (the table's, read from the file), everything else at Mitsuba's defaults, except
direct on the one scene whose own integrator is direct (hello.xml: its emitter_samples 4,
bsdf_samples 0; Mitsuba's direct counts its point light 4 times, so the test compares candela's
direct with the path reference there, docs/lights.md). The particle tracer has no reference where Mitsuba's cannot see the scene (the
orthographic sensor: a delta sensor that no light path can hit) or is wrong (under an environment
map Mitsuba 3.9's ptracer is 2.2-2.5x its own path tracer).

The committed references: mdata_cbox_rgb_fragments with --spp 1024 (path, direct; ptracer 4096),
bitterli_veach_mis with --spp 2048 (its small lights), the other scenes with --spp 256 (ptracer
1024), 16 batches, llvm_ad_rgb, Mitsuba 3.9.1:
  $PY tests/data/make_matrix_reference.py --only mdata_cbox_rgb_fragments --spp 1024
  $PY tests/data/make_matrix_reference.py --only bitterli_veach_mis --spp 2048
  $PY tests/data/make_matrix_reference.py --only SCENE --spp 256      (each other scene)
"""
import argparse
import os
import re
import shutil
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ASSETS = os.path.normpath(os.path.join(HERE, "..", "..", "assets", "scenes-public"))
OUT = os.path.join(HERE, "matrix")

# folder, main file, width, height, Mitsuba max_depth of the scene's integrator (-1 unbounded; hello.xml's
# direct integrator: 2, which candela's --integrator keeps, render/launch.cpp),
# the scene's own direct parameters (None: Mitsuba's defaults), ptracer possible.
# tests/test_matrix.cpp has the same table.
SCENES = [
    ("mdata_cbox_rgb_fragments", "cbox-rgb.xml", 24, 24, 6, None, True),
    ("mdata_hello_teapot", "scenes/hello.xml", 32, 24, 2, {"emitter_samples": 4, "bsdf_samples": 0}, True),
    ("mdata_matpreview", "matpreview.xml", 32, 24, -1, None, False),
    ("mdata_docs_bsdf_bumpmap_with", "docs/scenes/bsdf_bumpmap_with.xml", 32, 24, -1, None, False),
    ("mdata_test_instancing", "tests/scenes/instancing/test_instancing_path.xml", 24, 24, 2, None, True),
    ("mdata_test_orthographic", "test_orthographic_path.xml", 30, 18, 2, None, False),
    ("tutorials_cbox", "cbox.xml", 24, 24, 6, None, True),
    ("sionna_floor_wall", "floor_wall.xml", 32, 18, 12, None, True),
    ("bitterli_veach_mis", "scene.xml", 32, 18, 3, None, True),
    ("blender_export_test1", "test1.xml", 32, 18, 2, None, True),
]

FILM = re.compile(r"<film\b.*?</film>", re.S)
DIM = re.compile(r'(<integer\s+name="(width|height)"\s+value=")([^"]*)(")')


def shrink(folder, dst, w, h):
    """A copy of the scene folder whose films are w x h."""
    shutil.copytree(os.path.join(ASSETS, folder), dst)
    for d, _, fs in os.walk(dst):
        for f in fs:
            if not f.endswith(".xml"):
                continue
            p = os.path.join(d, f)
            t = open(p, encoding="utf-8", errors="replace").read()
            t2 = FILM.sub(lambda m: DIM.sub(lambda n: n.group(1) + str(w if n.group(2) == "width" else h) + n.group(4),
                                            m.group(0)), t)
            if t2 != t:
                open(p, "w", encoding="utf-8").write(t2)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--only")
    ap.add_argument("--integrators", default="path,direct,ptracer")
    ap.add_argument("--batches", type=int, default=16)
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    a = ap.parse_args()
    import mitsuba as mi
    mi.set_variant(a.variant)
    os.makedirs(OUT, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix="candela-matrix-")
    try:
        for folder, main_xml, w, h, depth, direct, ptracer in SCENES:
            if a.only and folder != a.only:
                continue
            shrink(folder, os.path.join(tmp, folder), w, h)
            scene = mi.load_file(os.path.join(tmp, folder, main_xml))
            for integ in a.integrators.split(","):
                if integ == "ptracer" and not ptracer:
                    continue
                if integ == "direct":
                    desc = dict({"type": "direct"}, **(direct or {}))
                else:
                    desc = {"type": integ, "max_depth": depth}
                integrator = mi.load_dict(desc)
                spp = a.spp * (4 if integ == "ptracer" else 1)
                imgs = [np.array(mi.render(scene, integrator=integrator, spp=spp, seed=k + 1), dtype=np.float64)[:, :, :3]
                        for k in range(a.batches)]
                stack = np.stack(imgs)
                mean = stack.mean(axis=0)
                var_of_mean = stack.var(axis=0, ddof=1) / a.batches
                prefix = os.path.join(OUT, "%s_%s" % (folder, integ))
                mi.Bitmap(mean.astype(np.float32)).write(prefix + "_mean.exr")
                mi.Bitmap(var_of_mean.astype(np.float32)).write(prefix + "_var.exr")
                m = mean.reshape(-1, 3).mean(axis=0)
                se = np.sqrt(var_of_mean.reshape(-1, 3).sum(axis=0)) / (w * h)
                print("%s_%s: %d x %d, %d batches x %d spp, mean RGB %s, whole-image se %s" %
                      (folder, integ, w, h, a.batches, spp, m, se), flush=True)
    finally:
        shutil.rmtree(tmp)


if __name__ == "__main__":
    main()
