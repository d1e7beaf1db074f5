#!/usr/bin/env python3
"""Writes data/scenes/room/room.obj: the sample proxy room, a 6 x 3 x 5 m box whose
faces point inward, with a table-sized block (faces outward). Metres, +Y up."""
import pathlib

verts, faces = [], []


def quad(a, b, c, d):
    base = len(verts) + 1
    verts.extend([a, b, c, d])
    faces.extend([(base, base + 1, base + 2), (base, base + 2, base + 3)])


def box(lo, hi, inward):
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    sides = [  # counter-clockwise seen from outside
        ((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)),  # -y
        ((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)),  # +y
        ((x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)),  # -z
        ((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)),  # +z
        ((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)),  # -x
        ((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)),  # +x
    ]
    for s in sides:
        quad(*(reversed(s) if inward else s))


box((-3.0, 0.0, -2.5), (3.0, 3.0, 2.5), inward=True)
box((0.55, 0.0, -1.1), (1.25, 0.72, -0.25), inward=False)
out = pathlib.Path(__file__).resolve().parent.parent / "data/scenes/room/room.obj"
with open(out, "w") as f:
    f.write("# Lumar sample proxy room: 6 x 3 x 5 m box (faces inward) and a table block\n")
    f.write("# (faces outward). Metres, +Y up. Written by scripts/make_sample_room.py.\n")
    for v in verts:
        f.write("v %g %g %g\n" % v)
    for t in faces:
        f.write("f %d %d %d\n" % t)
print(f"{out}: {len(verts)} vertices, {len(faces)} triangles")
