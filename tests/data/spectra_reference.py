#!/usr/bin/env python3
"""Prints Mitsuba 3's linear-sRGB values for the <spectrum> cases of
tests/test_scene_xml_structure.cpp (SpectraMatchMitsuba): each spectrum is loaded in a tiny scene
with the scalar_rgb variant and the converted texture is read back with mi.traverse.

    $PY tests/data/spectra_reference.py      (PY: the Python with Mitsuba 3.9.1)
"""
import mitsuba as mi

mi.set_variant("scalar_rgb")
CASES = [
    ("bsdf", "400:0.1, 500:0.5, 600:0.8, 700:0.3"),
    ("bsdf", "360:0.5, 830:0.5"),
    ("bsdf", "540:0, 550:1, 560:0"),
    ("bsdf", "300:0.2 900:0.9"),
    ("bsdf", "0.25"),
    ("emitter", "400:1, 700:2"),
    ("emitter", "500:0, 550:10, 600:0"),
    ("emitter", "3"),
    ("eta", "400:1.5, 550:0.9, 700:0.2"),
]
for where, value in CASES:
    if where == "emitter":
        body = f'<shape type="rectangle"><emitter type="area"><spectrum name="radiance" value="{value}"/></emitter></shape>'
    else:
        plugin, name = ("diffuse", "reflectance") if where == "bsdf" else ("conductor", "eta")
        body = (f'<bsdf type="{plugin}" id="b"><spectrum name="{name}" value="{value}"/></bsdf>'
                '<shape type="rectangle"><ref id="b"/></shape>')
    params = mi.traverse(mi.load_string(f'<scene version="3.0.0">{body}</scene>'))
    key = next(k for k in params.keys() if k.endswith(("radiance.value", "reflectance.value", "eta.value")))
    v = params[key]
    try:
        rgb = [float(v[i]) for i in range(3)]
    except TypeError:
        rgb = [float(v)] * 3
    print(f'{where:8s} {value!r:40s} vec3({", ".join("%.7gf" % c for c in rgb)})')
