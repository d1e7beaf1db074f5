#!/usr/bin/env python3
"""Writes data/scenes/courtyard/{ground,sphere}.obj: the courtyard scene's proxy, a 20 x 20 m
ground plane at y = 0 facing up (8 x 8 quads), and a sphere of radius 0.15 m resting on
it at the origin (24 stacks, 48 slices). Metres, +Y up, counter-clockwise = front."""
import math
import pathlib

out = pathlib.Path(__file__).resolve().parent.parent / "data" / "scenes" / "courtyard"


def write(name, comment, verts, faces):
    with open(out / name, "w") as f:
        f.write(f"# {comment} Written by scripts/make_courtyard_meshes.py.\n")
        # Rounded, so that a pole's copies are one point (sin(pi) is 1.2e-16, not 0): the
        # sphere is closed (tests/solid, ShippedModels).
        f.writelines("v %s %s %s\n" % tuple(f"{round(c, 12) + 0.0:g}" for c in v) for v in verts)
        f.writelines(f"f {a} {b} {c}\n" for a, b, c in faces)


n, half = 8, 10.0
verts = [(-half + 2 * half * i / n, 0.0, -half + 2 * half * j / n) for j in range(n + 1) for i in range(n + 1)]
faces = []
for j in range(n):
    for i in range(n):
        a = j * (n + 1) + i + 1
        b, c = a + 1, a + n + 1
        faces += [(a, c, c + 1), (a, c + 1, b)]  # counter-clockwise seen from above
write("ground.obj", "Courtyard ground: 20 x 20 m at y = 0, facing up.", verts, faces)

r, stacks, slices = 0.15, 24, 48
verts = [(r * math.sin(math.pi * i / stacks) * math.cos(2 * math.pi * k / slices),
          r + r * math.cos(math.pi * i / stacks),
          r * math.sin(math.pi * i / stacks) * math.sin(2 * math.pi * k / slices))
         for i in range(stacks + 1) for k in range(slices)]
faces = []
for i in range(stacks):
    for k in range(slices):
        a, b = i * slices + k + 1, i * slices + (k + 1) % slices + 1
        c, d = a + slices, b + slices
        faces += [(a, b, d), (a, d, c)]
write("sphere.obj", "A sphere of radius 0.15 m resting on y = 0.", verts, faces)
