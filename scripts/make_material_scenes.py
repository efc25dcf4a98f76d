#!/usr/bin/env python3
"""Generates the meshes and XML of the material scenes (issue 5): the Veach MIS scene and the caustic
scene with a glass sphere and a brilliant-cut diamond. Run from anywhere; writes into scenes/.

  python3 scripts/make_material_scenes.py

Every mesh is closed or one-sided as its BSDF needs: spheres and the diamond wound outwards (a
dielectric's outside is its normal's side), plates and the floor wound towards the camera.
The files are committed; rerun this only to change the scenes.
"""
import math
import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def sub(a, b): return (a[0] - b[0], a[1] - b[1], a[2] - b[2])
def add(a, b): return (a[0] + b[0], a[1] + b[1], a[2] + b[2])
def mul(a, s): return (a[0] * s, a[1] * s, a[2] * s)
def dot(a, b): return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
def cross(a, b): return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
def norm(a):
    l = math.sqrt(dot(a, a))
    return (a[0] / l, a[1] / l, a[2] / l)


def write_obj(path, verts, tris, normals=None, comment=""):
    with open(path, "w") as f:
        if comment:
            f.write("# %s\n" % comment)
        for v in verts:
            f.write("v %.7g %.7g %.7g\n" % v)
        if normals:
            for n in normals:
                f.write("vn %.7g %.7g %.7g\n" % n)
            for t in tris:
                f.write("f %d//%d %d//%d %d//%d\n" % (t[0] + 1, t[0] + 1, t[1] + 1, t[1] + 1, t[2] + 1, t[2] + 1))
        else:
            for t in tris:
                f.write("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1))


def orient_outward(verts, tris, center):
    """Winds every triangle so that its normal points away from `center` (star-shaped solids)."""
    out = []
    for t in tris:
        a, b, c = verts[t[0]], verts[t[1]], verts[t[2]]
        n = cross(sub(b, a), sub(c, a))
        g = mul(add(add(a, b), c), 1.0 / 3.0)
        out.append(t if dot(n, sub(g, center)) > 0 else (t[0], t[2], t[1]))
    return out


def icosphere(center, radius, subdiv):
    t = (1.0 + math.sqrt(5.0)) / 2.0
    verts = [norm(v) for v in [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
                               (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
             (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdiv):
        cache = {}
        def mid(i, j):
            key = (min(i, j), max(i, j))
            if key not in cache:
                verts.append(norm(mul(add(verts[i], verts[j]), 0.5)))
                cache[key] = len(verts) - 1
            return cache[key]
        nf = []
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = nf
    normals = list(verts)
    pos = [add(center, mul(v, radius)) for v in verts]
    return pos, orient_outward(pos, faces, center), normals


def brilliant(radius=1.0):
    """A round brilliant cut with Tolkowsky's proportions (in girdle radii): table 0.53, crown angle
    34.5 degrees, pavilion angle 40.75 degrees, a thin girdle. 8-fold symmetry: the octagonal table,
    8 bezel (kite) points on the crown, a 16-sided girdle, 8 pavilion main points and the culet.
    Every facet is a planar triangle. Centred on the girdle's middle, table up (+y)."""
    g = 0.02                                     # half girdle thickness
    r_table = 0.53
    crown_h = (1.0 - r_table) * math.tan(math.radians(34.5))
    pav_d = math.tan(math.radians(40.75))
    V = []
    def ring(n, r, y, phase):
        start = len(V)
        for k in range(n):
            a = 2 * math.pi * k / n + phase
            V.append((r * math.cos(a), y, r * math.sin(a)))
        return start
    table = ring(8, r_table, g + crown_h, 0.0)
    # Bezel points: halfway up the crown, on the cone, between table corners.
    bezel = ring(8, (1.0 + r_table) / 2.0 * 1.02, g + crown_h / 2.0, math.pi / 8)
    gtop = ring(16, 1.0, g, 0.0)
    gbot = ring(16, 1.0, -g, 0.0)
    pav = ring(8, 0.45, -g - pav_d * (1.0 - 0.45), math.pi / 8)
    V.append((0.0, -g - pav_d, 0.0))
    culet = len(V) - 1
    V.append((0.0, g + crown_h, 0.0))
    top = len(V) - 1
    T = []
    for k in range(8):
        k1 = (k + 1) % 8
        T.append((top, table + k, table + k1))                 # table (a fan: one plane)
        T.append((table + k, bezel + k, table + k1))           # star facets
        T.append((table + k, gtop + 2 * k, bezel + k))         # bezel (kite) halves
        T.append((table + k1, bezel + k, gtop + 2 * k1 % 16))
        T.append((bezel + k, gtop + 2 * k, gtop + 2 * k + 1))  # upper girdle facets
        T.append((bezel + k, gtop + 2 * k + 1, gtop + (2 * k + 2) % 16))
        T.append((culet, pav + k, pav + k1))                   # pavilion mains (lower part)
        T.append((pav + k, gbot + 2 * k + 1, gbot + 2 * k))    # lower girdle facets
        T.append((pav + k, gbot + (2 * k + 2) % 16, gbot + 2 * k + 1))
        T.append((pav + k, pav + k1, gbot + (2 * k + 2) % 16))
    for k in range(16):                                        # the girdle band
        k1 = (k + 1) % 16
        T.append((gtop + k, gbot + k, gbot + k1))
        T.append((gtop + k, gbot + k1, gtop + k1))
    V = [mul(v, radius) for v in V]
    return V, orient_outward(V, T, (0.0, 0.0, 0.0))


def quad(p0, p1, p2, p3):
    return [p0, p1, p2, p3], [(0, 1, 2), (0, 2, 3)]


def toward(verts, tris, point):
    """Winds the (planar) triangles so that their normal faces `point`."""
    out = []
    for t in tris:
        a, b, c = verts[t[0]], verts[t[1]], verts[t[2]]
        n = cross(sub(b, a), sub(c, a))
        out.append(t if dot(n, sub(point, a)) > 0 else (t[0], t[2], t[1]))
    return out


SENSOR = """    <sensor type="perspective">
        <float name="fov" value="{fov}"/>
        <string name="fov_axis" value="x"/>
        <transform name="to_world">
            <lookat origin="{origin}" target="{target}" up="0, 1, 0"/>
        </transform>
        <sampler type="independent">
            <integer name="sample_count" value="$spp"/>
            <integer name="seed" value="$seed"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="$width"/>
            <integer name="height" value="$height"/>
            <rfilter type="box"/>
            <string name="pixel_format" value="rgb"/>
        </film>
    </sensor>
"""

HEADER = """<?xml version="1.0" encoding="utf-8"?>
<!-- {comment}
     Generated by scripts/make_material_scenes.py. Renders in candela and in Mitsuba 3. -->
<scene version="3.0.0">
    <default name="spp" value="{spp}"/>
    <default name="width" value="{w}"/>
    <default name="height" value="{h}"/>
    <default name="max_depth" value="-1"/>
    <default name="seed" value="0"/>
    <integrator type="path">
        <integer name="max_depth" value="$max_depth"/>
    </integrator>
"""


def fmt(v): return "%g, %g, %g" % v


def veach_mis():
    d = os.path.join(ROOT, "scenes", "veach-mis")
    os.makedirs(d, exist_ok=True)
    cam, target = (0.0, 2.0, 15.0), (0.0, -1.0, 1.5)
    light_row = (0.0, 3.0, -3.0)                  # the lights sit in a row along x through here
    xml = HEADER.format(comment="The Veach MIS scene (Veach 1997, figure 9.2): four glossy plates of "
                        "increasing roughness (GGX alpha 0.01, 0.03, 0.08, 0.2, back to front) reflect four "
                        "spherical lights of increasing size and equal power. Light sampling wins on the rough "
                        "plates and large lights, BSDF sampling on the smooth plates and small lights; MIS "
                        "(the default) is good everywhere. Try candela --sampling light|bsdf|mis.",
                        spp=64, w=384, h=256)
    xml += SENSOR.format(fov=46, origin=fmt(cam), target=fmt(target))
    # Plates from back (top) to front (bottom); each is tilted so that it mirrors the light row
    # towards the camera.
    plates = [((0.0, -0.2, 0.0), 0.01), ((0.0, -1.4, 1.6), 0.03), ((0.0, -2.4, 3.3), 0.08), ((0.0, -3.2, 5.1), 0.2)]
    for i, (c, alpha) in enumerate(plates):
        h = norm(add(norm(sub(cam, c)), norm(sub(light_row, c))))
        t = norm(cross(h, (1.0, 0.0, 0.0)))
        hx, ht = 4.0, 0.55
        corners = [add(c, add(mul((1.0, 0.0, 0.0), sx * hx), mul(t, st * ht))) for sx, st in [(-1, -1), (1, -1), (1, 1), (-1, 1)]]
        v, tr = quad(*corners)
        write_obj(os.path.join(d, "plate%d.obj" % i), v, toward(v, tr, add(c, h)), comment="plate %d, facing the camera" % i)
        xml += """    <shape type="obj">
        <string name="filename" value="plate{i}.obj"/>
        <boolean name="face_normals" value="true"/>
        <bsdf type="roughconductor">
            <string name="distribution" value="ggx"/>
            <float name="alpha" value="{a}"/>
            <rgb name="specular_reflectance" value="0.35, 0.35, 0.35"/>
        </bsdf>
    </shape>
""".format(i=i, a=alpha)
    # Lights: radii 0.03, 0.1, 0.3, 0.9 with radiance ~ 1 / r^2 (equal power), four colours.
    radii = [0.03, 0.1, 0.3, 0.9]
    xs = [-3.75, -1.25, 1.25, 3.75]
    colours = [(1.0, 0.55, 0.35), (0.5, 1.0, 0.4), (0.4, 0.6, 1.0), (1.0, 0.9, 0.6)]
    for i, (r, x, col) in enumerate(zip(radii, xs, colours)):
        v, tr, n = icosphere((x, light_row[1], light_row[2]), r, 3)
        write_obj(os.path.join(d, "light%d.obj" % i), v, tr, n, comment="sphere light %d, radius %g" % (i, r))
        L = mul(col, 0.8 * (0.9 / r) ** 2 / 0.9)
        xml += """    <shape type="obj">
        <string name="filename" value="light{i}.obj"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
        <emitter type="area"><rgb name="radiance" value="{L}"/></emitter>
    </shape>
""".format(i=i, L=fmt(L))
    # No backdrop, as in Veach's figure: everything seen is a light or its reflection in a plate.
    xml += "</scene>\n"
    open(os.path.join(d, "scene.xml"), "w").write(xml)


def caustics():
    d = os.path.join(ROOT, "scenes", "caustics")
    os.makedirs(d, exist_ok=True)
    cam, target = (0.0, 4.5, 7.5), (0.0, 0.4, 0.0)
    xml = HEADER.format(comment="Caustics: a glass sphere (IOR 1.5) and a brilliant-cut diamond (IOR 2.42) on a "
                        "diffuse floor under a small area light. Needs many samples (>= 1024 spp) or the "
                        "bidirectional methods.", spp=256, w=512, h=384)
    xml += SENSOR.format(fov=40, origin=fmt(cam), target=fmt(target))
    v, tr = quad((-6.0, 0.0, -6.0), (6.0, 0.0, -6.0), (6.0, 0.0, 6.0), (-6.0, 0.0, 6.0))
    write_obj(os.path.join(d, "floor.obj"), v, toward(v, tr, (0.0, 1.0, 0.0)), comment="floor, facing up")
    v, tr, n = icosphere((-1.1, 1.0, 0.0), 1.0, 4)
    write_obj(os.path.join(d, "sphere.obj"), v, tr, n, comment="glass sphere, radius 1, smooth normals")
    v, tr = brilliant(0.9)
    # Table up, tilted a little so that the pavilion does not stand on its culet alone: it rests
    # on the floor with the lowest point at y = 0, slightly rotated about z.
    ang = math.radians(-35.0)
    rot = [(x * math.cos(ang) - y * math.sin(ang), x * math.sin(ang) + y * math.cos(ang), z) for x, y, z in v]
    low = min(p[1] for p in rot)
    rot = [(x + 1.3, y - low, z + 0.4) for x, y, z in rot]
    write_obj(os.path.join(d, "diamond.obj"), rot, tr, comment="brilliant cut (Tolkowsky proportions), flat facets")
    v, tr = quad((-0.25, 5.0, -0.25), (0.25, 5.0, -0.25), (0.25, 5.0, 0.25), (-0.25, 5.0, 0.25))
    v = [(x + 0.5, y, z - 1.5) for x, y, z in v]
    write_obj(os.path.join(d, "light.obj"), v, toward(v, tr, (0.5, 0.0, -1.5)), comment="small light, facing down")
    xml += """    <shape type="obj">
        <string name="filename" value="floor.obj"/>
        <boolean name="face_normals" value="true"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.6, 0.6, 0.6"/></bsdf>
    </shape>
    <shape type="obj">
        <string name="filename" value="sphere.obj"/>
        <bsdf type="dielectric"><float name="int_ior" value="1.5"/></bsdf>
    </shape>
    <shape type="obj">
        <string name="filename" value="diamond.obj"/>
        <boolean name="face_normals" value="true"/>
        <bsdf type="dielectric"><float name="int_ior" value="2.42"/></bsdf>
    </shape>
    <shape type="obj">
        <string name="filename" value="light.obj"/>
        <boolean name="face_normals" value="true"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
        <emitter type="area"><rgb name="radiance" value="400, 380, 340"/></emitter>
    </shape>
</scene>
"""
    open(os.path.join(d, "scene.xml"), "w").write(xml)


if __name__ == "__main__":
    veach_mis()
    caustics()
