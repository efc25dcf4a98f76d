#!/usr/bin/env python3
"""Writes tests/data/public_meshes.txt: what Mitsuba 3 reads from the public scenes' PLY and
serialized meshes (object space, no to_world), for test_mesh_formats to compare candela's readers
against. One line per mesh:
  path shape_index vertices faces has_normals has_uv  bbox_min(3) bbox_max(3)
  v[0](3) v[n/2](3) v[n-1](3)  uv[0](2) uv[n-1](2)  face[0](3) face[last](3)
path is relative to assets/scenes-public. Usage: $PY tests/data/make_mesh_reference.py
"""
import os
import numpy as np
import mitsuba as mi

HERE = os.path.dirname(os.path.abspath(__file__))
PUBLIC = os.path.normpath(os.path.join(HERE, "..", "..", "assets", "scenes-public"))
MESHES = [
    ("mdata_hello_teapot/common/meshes/teapot.ply", 0),
    ("sionna_floor_wall/meshes/floor.ply", 0),
    ("sionna_floor_wall/meshes/wall.ply", 0),
    ("blender_export_test1/meshes/Cube.ply", 0),
    ("mdata_matpreview/matpreview.serialized", 0),
    ("mdata_matpreview/matpreview.serialized", 1),
    ("mdata_matpreview/matpreview.serialized", 2),
]


def main():
    mi.set_variant("scalar_rgb")
    lines = []
    for path, index in MESHES:
        d = {"type": "ply" if path.endswith(".ply") else "serialized", "filename": os.path.join(PUBLIC, path)}
        if d["type"] == "serialized":
            d["shape_index"] = index
        m = mi.load_dict(d)
        p = np.array(m.vertex_positions_buffer(), dtype=np.float64).reshape(-1, 3)
        f = np.array(m.faces_buffer(), dtype=np.int64).reshape(-1, 3)
        uv = np.array(m.vertex_texcoords_buffer(), dtype=np.float64).reshape(-1, 2)
        # has_normals: the mesh has vertex normals, read from the file or computed by Mitsuba
        n = len(p)
        vals = [path, index, n, len(f), int(m.has_vertex_normals()), int(m.has_vertex_texcoords())]
        vals += list(p.min(axis=0)) + list(p.max(axis=0)) + list(p[0]) + list(p[n // 2]) + list(p[-1])
        vals += list(uv[0]) + list(uv[-1]) if len(uv) else [0, 0, 0, 0]
        vals += list(f[0]) + list(f[-1])
        lines.append(" ".join(repr(float(v)) if isinstance(v, (float, np.floating)) else str(v) for v in vals))
    with open(os.path.join(HERE, "public_meshes.txt"), "w") as out:
        out.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
