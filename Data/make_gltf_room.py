#!/usr/bin/python3
"""Writes a small glTF 2.0 room with its materials, for the material-aware scene reader and
Examples/material_scenes.py.

    /usr/bin/python3 Data/make_gltf_room.py [OUTPUT_DIR]     (default: next to this script)

Geometry, in metres as glTF has it (y up): a room 4 m wide (x 0 to 4), 2.5 m high (y) and
3 m deep (z 0 to 3), open towards +z where the camera stands; a box 1.1 x 1.2 x 1.1 m turned
25 degrees about y; and a ceiling panel 0.6 x 0.6 m hanging 1 cm below the ceiling, facing
down. Every wall faces into the room, the box's faces face away from it.

Materials (name: baseColorFactor; emitted radiance): floor 0.70 0.70 0.65; backWall and
ceiling 0.725 0.71 0.68; redWall (x = 0) 0.63 0.065 0.05; blueWall (x = 4) 0.10 0.20 0.60;
box 0.20 0.55 0.15; panel 0.78 0.78 0.78 with emissiveFactor 1 0.9 0.7 and
KHR_materials_emissive_strength 20, which the reader takes as the radiance 20 18 14
W/(m^2 sr), like OBJ's Ke: the panel emits pi x 20 x 0.36 = 22.6 W in red.

Output: room.gltf, its buffer embedded as a base64 data: URI (about 5 kB).
"""
import base64
import json
import math
import os
import struct
import sys

WHITE = [0.725, 0.71, 0.68]
# name, baseColorFactor (RGB), emissiveFactor, emissive strength
MATERIALS = [
    ("floor", [0.70, 0.70, 0.65], None, None),
    ("backWall", WHITE, None, None),
    ("ceiling", WHITE, None, None),
    ("redWall", [0.63, 0.065, 0.05], None, None),
    ("blueWall", [0.10, 0.20, 0.60], None, None),
    ("box", [0.20, 0.55, 0.15], None, None),
    ("panel", [0.78, 0.78, 0.78], [1.0, 0.9, 0.7], 20.0),
]
WIDTH, HEIGHT, DEPTH = 4.0, 2.5, 3.0
PANEL_CENTRE = (1.0, HEIGHT - 0.01, 1.5)
PANEL_HALF = 0.3
BOX_CENTRE, BOX_HALF, BOX_HEIGHT, BOX_TURN = (2.7, 1.3), 0.55, 1.2, math.radians(25)


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def quad(corners, facing):
    """Two triangles over four corners in order around the quad, wound so that their normal
    (counter-clockwise, as glTF's front faces) points along `facing`."""
    normal = cross(sub(corners[1], corners[0]), sub(corners[2], corners[0]))
    if sum(n * f for n, f in zip(normal, facing)) < 0:
        corners = corners[::-1]
    return corners, [(0, 1, 2), (0, 2, 3)]


def room_quads():
    """Quads per material, as (corners, facing direction)."""
    w, h, d = WIDTH, HEIGHT, DEPTH
    quads = {
        "floor": [([(0, 0, 0), (w, 0, 0), (w, 0, d), (0, 0, d)], (0, 1, 0))],
        "ceiling": [([(0, h, 0), (w, h, 0), (w, h, d), (0, h, d)], (0, -1, 0))],
        "backWall": [([(0, 0, 0), (w, 0, 0), (w, h, 0), (0, h, 0)], (0, 0, 1))],
        "redWall": [([(0, 0, 0), (0, h, 0), (0, h, d), (0, 0, d)], (1, 0, 0))],
        "blueWall": [([(w, 0, 0), (w, h, 0), (w, h, d), (w, 0, d)], (-1, 0, 0))],
    }
    # The box: four sides and a top, each facing away from the box's axis.
    cx, cz = BOX_CENTRE
    c, s = math.cos(BOX_TURN), math.sin(BOX_TURN)
    footprint = [(cx + c * x - s * z, cz + s * x + c * z)
                 for x, z in ((-BOX_HALF, -BOX_HALF), (BOX_HALF, -BOX_HALF),
                              (BOX_HALF, BOX_HALF), (-BOX_HALF, BOX_HALF))]
    box = []
    for i in range(4):
        (x0, z0), (x1, z1) = footprint[i], footprint[(i + 1) % 4]
        outward = ((x0 + x1) / 2 - cx, 0, (z0 + z1) / 2 - cz)
        box.append(([(x0, 0, z0), (x1, 0, z1), (x1, BOX_HEIGHT, z1), (x0, BOX_HEIGHT, z0)], outward))
    box.append(([(x, BOX_HEIGHT, z) for x, z in footprint], (0, 1, 0)))
    quads["box"] = box
    px, py, pz = PANEL_CENTRE
    quads["panel"] = [([(px - PANEL_HALF, py, pz - PANEL_HALF), (px + PANEL_HALF, py, pz - PANEL_HALF),
                        (px + PANEL_HALF, py, pz + PANEL_HALF), (px - PANEL_HALF, py, pz + PANEL_HALF)],
                       (0, -1, 0))]
    return quads


def document():
    binary = bytearray()
    buffer_views, accessors, primitives = [], [], []

    def add_view(data, target):
        while len(binary) % 4:
            binary.append(0)
        buffer_views.append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(data),
                             "target": target})
        binary.extend(data)
        return len(buffer_views) - 1

    quads = room_quads()
    for index, (name, _, _, _) in enumerate(MATERIALS):
        points, triangles = [], []
        for corners, facing in quads[name]:
            ordered, local = quad([list(map(float, p)) for p in corners], facing)
            triangles += [tuple(len(points) + k for k in t) for t in local]
            points += ordered
        positions = add_view(b"".join(struct.pack("<3f", *p) for p in points), 34962)
        indices = add_view(b"".join(struct.pack("<3H", *t) for t in triangles), 34963)
        accessors.append({"bufferView": positions, "componentType": 5126, "count": len(points),
                          "type": "VEC3",
                          "min": [min(p[i] for p in points) for i in range(3)],
                          "max": [max(p[i] for p in points) for i in range(3)]})
        accessors.append({"bufferView": indices, "componentType": 5123,
                          "count": 3 * len(triangles), "type": "SCALAR"})
        primitives.append({"attributes": {"POSITION": len(accessors) - 2},
                           "indices": len(accessors) - 1, "material": index, "mode": 4})

    materials = []
    for name, base, emissive, strength in MATERIALS:
        material = {"name": name, "pbrMetallicRoughness": {
            "baseColorFactor": base + [1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}
        if emissive:
            material["emissiveFactor"] = emissive
            material["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}
        materials.append(material)

    return {
        "asset": {"version": "2.0", "generator": "MovingLightRadiosity Data/make_gltf_room.py"},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"name": "room", "nodes": [0]}],
        "nodes": [{"name": "room", "mesh": 0}],
        "meshes": [{"name": "room", "primitives": primitives}],
        "materials": materials,
        "accessors": accessors,
        "bufferViews": buffer_views,
        "buffers": [{"byteLength": len(binary),
                     "uri": "data:application/octet-stream;base64,"
                            + base64.b64encode(bytes(binary)).decode("ascii")}],
    }


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    path = os.path.join(folder, "room.gltf")
    with open(path, "w") as out:
        json.dump(document(), out, indent=1)
        out.write("\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
