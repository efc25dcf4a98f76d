#!/usr/bin/env python3
"""Makes the committed camera data of tests/test_cameras.cpp with Mitsuba 3 (3.9.1):

  rays.txt   for each sensor below (an XML snippet that candela reads too), the ray Mitsuba's own
             sensor.sample_ray gives through a few pixel centres (and lens samples for the thin lens):
             origin, direction, and the ray's length maxt, as numbers.
  *_mean.exr, *_var.exr
             the references of the camera scenes in this folder (perspective.xml, thinlens.xml,
             orthographic.xml), through tests/data/make_reference.py.

Usage (PY from ../shared/tools/setup-reference.sh), from the repository root:
  $PY tests/data/cameras/make_camera_data.py [--rays-only]
"""
import argparse, os, subprocess, sys

HERE = os.path.dirname(os.path.abspath(__file__))

LOOK = '<transform name="to_world"><lookat origin="1, 2, -3" target="0.2, 0.5, 1" up="0.1, 1, 0"/></transform>'
LOOK_SCALED = ('<transform name="to_world"><scale x="2" y="1.5"/>'
               '<lookat origin="1, 2, -3" target="0.2, 0.5, 1" up="0.1, 1, 0"/></transform>')


def film(w, h, crop=None):
    s = '<film type="hdrfilm"><integer name="width" value="%d"/><integer name="height" value="%d"/>' % (w, h)
    if crop:
        s += ('<integer name="crop_offset_x" value="%d"/><integer name="crop_offset_y" value="%d"/>'
              '<integer name="crop_width" value="%d"/><integer name="crop_height" value="%d"/>' % crop)
    return s + '<rfilter type="box"/></film>'


# (name, sensor type, parameters, film size, crop (x, y, w, h) or None)
CASES = [
    ("persp_x", "perspective", '<float name="fov" value="50"/>' + LOOK, (40, 30), None),
    ("persp_y_portrait", "perspective", '<float name="fov" value="30"/><string name="fov_axis" value="y"/>' + LOOK,
     (30, 40), None),
    ("persp_diagonal", "perspective", '<float name="fov" value="60"/><string name="fov_axis" value="diagonal"/>' + LOOK,
     (64, 32), None),
    ("persp_smaller_landscape", "perspective",
     '<float name="fov" value="35"/><string name="fov_axis" value="smaller"/>' + LOOK, (48, 32), None),
    ("persp_smaller_portrait", "perspective",
     '<float name="fov" value="35"/><string name="fov_axis" value="smaller"/>' + LOOK, (32, 48), None),
    ("persp_larger_landscape", "perspective",
     '<float name="fov" value="35"/><string name="fov_axis" value="larger"/>' + LOOK, (48, 32), None),
    ("persp_larger_portrait", "perspective",
     '<float name="fov" value="35"/><string name="fov_axis" value="larger"/>' + LOOK, (32, 48), None),
    ("persp_focal_35mm", "perspective", '<string name="focal_length" value="35mm"/>' + LOOK, (30, 20), None),
    ("persp_default_lens", "perspective", LOOK, (36, 36), None),
    ("persp_ppo_clip", "perspective",
     '<float name="fov" value="45"/><float name="principal_point_offset_x" value="0.1"/>'
     '<float name="principal_point_offset_y" value="-0.2"/><float name="near_clip" value="0.3"/>'
     '<float name="far_clip" value="50"/>' + LOOK, (40, 30), None),
    ("persp_crop_ppo", "perspective",
     '<float name="fov" value="45"/><float name="principal_point_offset_x" value="-0.05"/>'
     '<float name="principal_point_offset_y" value="0.07"/>' + LOOK, (40, 30), (5, 7, 20, 12)),
    ("thinlens", "thinlens",
     '<float name="fov" value="45"/><float name="aperture_radius" value="0.2"/>'
     '<float name="focus_distance" value="3"/><float name="near_clip" value="0.1"/>' + LOOK, (40, 30), None),
    ("thinlens_crop_focal", "thinlens",
     '<string name="focal_length" value="28mm"/><float name="aperture_radius" value="0.05"/>'
     '<float name="focus_distance" value="7"/>' + LOOK, (40, 30), (10, 3, 16, 20)),
    ("ortho", "orthographic", '<float name="near_clip" value="0.5"/><float name="far_clip" value="20"/>' + LOOK_SCALED,
     (40, 30), None),
    ("ortho_crop", "orthographic", LOOK_SCALED, (40, 30), (12, 9, 8, 16)),
]

LENS = [(0.5, 0.5), (0.1, 0.8), (0.93, 0.27)]


def sensor_xml(ty, params, size, crop):
    return '<sensor type="%s">%s%s</sensor>' % (ty, params, film(size[0], size[1], crop))


def rays():
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    out = ["# Made by tests/data/cameras/make_camera_data.py with Mitsuba %s (scalar_rgb)." % mi.__version__,
           "# case NAME, then the sensor's XML, then lines: ray i j lens_x lens_y  o.x o.y o.z  d.x d.y d.z  maxt",
           "# for the centre of image pixel (i, j) of the crop window; Mitsuba's ray starts at the near plane."]
    for name, ty, params, size, crop in CASES:
        xml = sensor_xml(ty, params, size, crop)
        scene = mi.load_string('<scene version="3.0.0">%s</scene>' % xml)
        s = scene.sensors()[0]
        cw, ch = (crop[2], crop[3]) if crop else size
        out.append("case " + name)
        out.append(xml)
        pixels = [(0, 0), (cw - 1, 0), (0, ch - 1), (cw - 1, ch - 1), (cw // 2, ch // 3), (cw // 3, ch - 2)]
        lenses = LENS if ty == "thinlens" else [(0.5, 0.5)]
        for (i, j) in pixels:
            for l in lenses:
                r, _ = s.sample_ray(0.0, 0.5, [(i + 0.5) / cw, (j + 0.5) / ch], list(l))
                out.append("ray %d %d %.9g %.9g  %.9g %.9g %.9g  %.9g %.9g %.9g  %.9g" %
                           ((i, j) + l + tuple(r.o) + tuple(r.d) + (r.maxt,)))
    open(os.path.join(HERE, "rays.txt"), "w").write("\n".join(out) + "\n")
    print("wrote rays.txt: %d cases" % len(CASES))


def references():
    root = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
    for name in ["perspective", "thinlens", "orthographic"]:
        subprocess.run([sys.executable, os.path.join(root, "tests", "data", "make_reference.py"),
                        os.path.join(HERE, name + ".xml"), "--res", "48", "--batches", "16", "--spp", "1024",
                        "--out", os.path.join(HERE, name)], check=True)


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--rays-only", action="store_true")
    a = ap.parse_args()
    rays()
    if not a.rays_only:
        references()
