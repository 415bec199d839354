#!/usr/bin/python3
"""Writes the Cornell box as a Wavefront OBJ with its MTL materials, in the style of the
public-domain CornellBox-Original.obj (Williams College, 2011): the lamp is a polygon of the
scene with the material `light` (Kd 0.78, Ke 17 12 4), as path tracers expect.

    /usr/bin/python3 Data/make_cornell_obj.py [OUTPUT_DIR]     (default: next to this script)

Geometry: the published Cornell box of make_cornell_box.py (millimetres), in the Williams
frame: y up, centred on x = z = 0, the camera side towards +z, red wall at x = -1, green wall
at x = +1, back wall at z = -1, scaled by 1/278 so that the room is about 2 units wide (the
unit is arbitrary; read it as metres). Every polygon faces into the room, box faces face away
from their box, the lamp hangs 0.01 below the ceiling facing down.

Materials (name: Kd; Ke): floor, ceiling, backWall, shortBox, tallBox: 0.725 0.71 0.68;
leftWall (red): 0.63 0.065 0.05; rightWall (green): 0.14 0.45 0.091; light: 0.78 0.78 0.78,
Ke 17 12 4 (radiance; vtkRadiositySceneReader gives it the exitance pi x Ke W/m^2).

Outputs: CornellBox-Original.obj and CornellBox-Original.mtl.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_cornell_box as cornell  # noqa: E402 (the published geometry and orientation)

NAME = "CornellBox-Original"
SCALE = 1.0 / 278.0        # millimetres to Williams units: 556 mm wide -> 2
CENTRE_X_MM = 278.0
CENTRE_Z_MM = 279.6
LIGHT_DROP = 0.01          # Williams units below the ceiling

WHITE = (0.725, 0.71, 0.68)
MATERIALS = [  # name, Kd, Ke
    ("floor", WHITE, (0, 0, 0)),
    ("ceiling", WHITE, (0, 0, 0)),
    ("backWall", WHITE, (0, 0, 0)),
    ("rightWall", (0.14, 0.45, 0.091), (0, 0, 0)),
    ("leftWall", (0.63, 0.065, 0.05), (0, 0, 0)),
    ("shortBox", WHITE, (0, 0, 0)),
    ("tallBox", WHITE, (0, 0, 0)),
    ("light", (0.78, 0.78, 0.78), (17, 12, 4)),
]
# make_cornell_box.ROOM names, in order, as Williams material names.
ROOM_MATERIALS = ["floor", "ceiling", "backWall", "rightWall", "leftWall"]


def williams(point):
    """A published point (mm) in the Williams frame: turned half a turn about y (x and z
    mirrored: a rotation, so windings keep their sense), centred and scaled."""
    x, y, z = point
    return (-(x - CENTRE_X_MM) * SCALE, y * SCALE, -(z - CENTRE_Z_MM) * SCALE)


def objects():
    """(object name, material, [polygons in the Williams frame, each wound as it faces])."""
    result = []
    room_centre = cornell.mean([p for _, _, polygon in cornell.ROOM for p in polygon])
    for (name, _, polygon), material in zip(cornell.ROOM, ROOM_MATERIALS):
        result.append((material, material, [cornell.oriented(name, polygon, room_centre)]))
    for material, block in (("shortBox", cornell.SHORT_BLOCK), ("tallBox", cornell.TALL_BLOCK)):
        inside = cornell.mean([p for polygon in block for p in polygon])
        faces = []
        for i, polygon in enumerate(block):
            centroid = cornell.mean(polygon)
            away = tuple(2 * c - m for c, m in zip(centroid, inside))
            faces.append(cornell.oriented(f"{material} face {i}", polygon, away))
        result.append((material, material, faces))
    drop_mm = LIGHT_DROP / SCALE
    lowered = [(x, y - drop_mm, z) for x, y, z in cornell.LIGHT]
    below = tuple(c + d for c, d in zip(cornell.mean(lowered), (0.0, -1.0, 0.0)))
    result.append(("light", "light", [cornell.oriented("light", lowered, below)]))
    return [(name, material, [[williams(p) for p in polygon] for polygon in polygons])
            for name, material, polygons in result]


def obj_text():
    lines = [
        "# The Cornell box in the style of CornellBox-Original.obj (Williams College, 2011),",
        "# from the published Cornell box data (www.graphics.cornell.edu/online/box/data.html).",
        "# Written by Data/make_cornell_obj.py; the lamp is the polygon of material 'light'.",
        f"mtllib {NAME}.mtl",
    ]
    for name, material, polygons in objects():
        lines += ["", f"## Object {name}"]
        for polygon in polygons:
            lines += ["v %9.4f %9.4f %9.4f" % p for p in polygon]
        lines += [f"g {name}", f"usemtl {material}"]
        offset = sum(len(p) for p in polygons)
        for polygon in polygons:
            lines.append("f " + " ".join(str(-offset + i) for i in range(len(polygon))))
            offset -= len(polygon)
    return "\n".join(lines) + "\n"


def mtl_text():
    lines = ["# Materials of CornellBox-Original.obj: Kd reflectance, Ke emitted radiance"]
    for name, kd, ke in MATERIALS:
        lines += ["", f"newmtl {name}", "Ns 10.0000", "Ni 1.5000", "illum 2",
                  "Ka %g %g %g" % kd, "Kd %g %g %g" % kd, "Ks 0 0 0", "Ke %g %g %g" % ke]
    return "\n".join(lines) + "\n"


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    os.makedirs(out, exist_ok=True)
    for extension, text in (("obj", obj_text()), ("mtl", mtl_text())):
        path = os.path.join(out, f"{NAME}.{extension}")
        with open(path, "w", encoding="ascii", newline="\n") as file:
            file.write(text)
        print(path)


if __name__ == "__main__":
    main()
