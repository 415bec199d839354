#!/usr/bin/python3
"""Writes the Cornell box scene, its ceiling light and a diagonal light trajectory as .vtp.

    /usr/bin/python3 Data/make_cornell_box.py [OUTPUT_DIR]     (default: next to this script)

The geometry is the published Cornell box (https://www.graphics.cornell.edu/online/box/data.html)
converted from millimetres to metres, y up, open at the front (z = 0). Its polygons are listed
as published, but the published winding is not consistent, so every polygon is oriented here:
room surfaces face the inside of the room, block faces face away from their block (out into the
room). The scene carries the cell array `Reflectance` (RGB in [0, 1)).

Outputs:
  cornell_box.vtp         the room and its two blocks, with `Reflectance`
  cornell_light.vtp       the 130 mm x 105 mm ceiling light, 1 mm below the ceiling, facing down
  cornell_trajectory.vtp  30 light-centroid positions on a diagonal just below the ceiling
"""
import os
import sys

from vtkmodules.vtkCommonCore import vtkFloatArray, vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter

RED = (0.63, 0.065, 0.05)
GREEN = (0.14, 0.45, 0.091)
WHITE = (0.75, 0.75, 0.75)

# Published vertices in millimetres.
ROOM = [
    ("floor", WHITE, [(552.8, 0, 0), (0, 0, 0), (0, 0, 559.2), (549.6, 0, 559.2)]),
    ("ceiling", WHITE, [(556, 548.8, 0), (556, 548.8, 559.2), (0, 548.8, 559.2), (0, 548.8, 0)]),
    ("back wall", WHITE,
     [(549.6, 0, 559.2), (0, 0, 559.2), (0, 548.8, 559.2), (556, 548.8, 559.2)]),
    ("right wall (green)", GREEN,
     [(0, 0, 559.2), (0, 0, 0), (0, 548.8, 0), (0, 548.8, 559.2)]),
    ("left wall (red)", RED,
     [(552.8, 0, 0), (549.6, 0, 559.2), (556, 548.8, 559.2), (556, 548.8, 0)]),
]
SHORT_BLOCK = [
    [(130, 165, 65), (82, 165, 225), (240, 165, 272), (290, 165, 114)],
    [(290, 0, 114), (290, 165, 114), (240, 165, 272), (240, 0, 272)],
    [(130, 0, 65), (130, 165, 65), (290, 165, 114), (290, 0, 114)],
    [(82, 0, 225), (82, 165, 225), (130, 165, 65), (130, 0, 65)],
    [(240, 0, 272), (240, 165, 272), (82, 165, 225), (82, 0, 225)],
]
TALL_BLOCK = [
    [(423, 330, 247), (265, 330, 296), (314, 330, 456), (472, 330, 406)],
    [(423, 0, 247), (423, 330, 247), (472, 330, 406), (472, 0, 406)],
    [(472, 0, 406), (472, 330, 406), (314, 330, 456), (314, 0, 456)],
    [(314, 0, 456), (314, 330, 456), (265, 330, 296), (265, 0, 296)],
    [(265, 0, 296), (265, 330, 296), (423, 330, 247), (423, 0, 247)],
]
LIGHT = [(343, 548.8, 227), (343, 548.8, 332), (213, 548.8, 332), (213, 548.8, 227)]
LIGHT_DROP_MM = 1.0  # below the ceiling, so that the light is not inside it

TRAJECTORY_POSITIONS = 30
# Light-centroid positions (metres), symmetric about the published light's centre
# (0.278, 0.2795) in x and z and far enough from the walls for the whole light to stay inside.
TRAJECTORY_START = (0.120, 0.5478, 0.0995)
TRAJECTORY_END = (0.436, 0.5478, 0.4595)


def subtract(a, b):
    return tuple(x - y for x, y in zip(a, b))


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def mean(points):
    return tuple(sum(c) / len(points) for c in zip(*points))


def newell_normal(polygon):
    """Area-weighted normal of a (possibly slightly non-planar) polygon, right-hand rule."""
    n = [0.0, 0.0, 0.0]
    for i, p in enumerate(polygon):
        q = polygon[(i + 1) % len(polygon)]
        n[0] += (p[1] - q[1]) * (p[2] + q[2])
        n[1] += (p[2] - q[2]) * (p[0] + q[0])
        n[2] += (p[0] - q[0]) * (p[1] + q[1])
    return tuple(n)


checked, flipped = [], []


def oriented(name, polygon, towards):
    """The polygon wound so that its normal points to the side of `towards`."""
    side = dot(newell_normal(polygon), subtract(towards, mean(polygon)))
    if side == 0:
        raise ValueError(f"{name}: cannot tell which way it faces")
    checked.append(name)
    if side > 0:
        return polygon
    flipped.append(name)
    return list(reversed(polygon))


def metres(polygon):
    return [tuple(c / 1000.0 for c in p) for p in polygon]


def polydata(polygons, reflectances=None, polyline=False):
    points = vtkPoints()
    points.SetDataTypeToDouble()
    cells = vtkCellArray()
    for polygon in polygons:
        cells.InsertNextCell(len(polygon))
        for p in polygon:
            cells.InsertCellPoint(points.InsertNextPoint(p))
    data = vtkPolyData()
    data.SetPoints(points)
    if polyline:
        data.SetLines(cells)
    else:
        data.SetPolys(cells)
    if reflectances is not None:
        array = vtkFloatArray()
        array.SetName("Reflectance")
        array.SetNumberOfComponents(3)
        for rho in reflectances:
            array.InsertNextTuple(rho)
        data.GetCellData().AddArray(array)
    return data


def scene():
    room_centre = mean([p for _, _, polygon in ROOM for p in polygon])
    polygons, reflectances = [], []
    for name, rho, polygon in ROOM:
        polygons.append(oriented(name, polygon, room_centre))
        reflectances.append(rho)
    for block_name, block in (("short block", SHORT_BLOCK), ("tall block", TALL_BLOCK)):
        inside = mean([p for polygon in block for p in polygon])
        for i, polygon in enumerate(block):
            # Away from the block: towards the mirror image of its centre.
            centroid = mean(polygon)
            away = tuple(2 * c - m for c, m in zip(centroid, inside))
            polygons.append(oriented(f"{block_name} face {i}", polygon, away))
            reflectances.append(WHITE)
    return polydata([metres(p) for p in polygons], reflectances)


def light():
    lowered = [(x, y - LIGHT_DROP_MM, z) for x, y, z in LIGHT]
    below = (0.0, -1.0, 0.0)
    polygon = oriented("light", lowered, tuple(c + b for c, b in zip(mean(lowered), below)))
    return polydata([metres(polygon)])


def trajectory():
    n = TRAJECTORY_POSITIONS
    points = [tuple(a + (b - a) * i / (n - 1) for a, b in zip(TRAJECTORY_START, TRAJECTORY_END))
              for i in range(n)]
    return polydata([points], polyline=True)


def write(data, path):
    writer = vtkXMLPolyDataWriter()
    writer.SetInputData(data)
    writer.SetFileName(path)
    writer.SetDataModeToAscii()  # small, and readable in a diff
    if not writer.Write():
        raise OSError(f"cannot write {path}")
    print(path)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    os.makedirs(out, exist_ok=True)
    write(scene(), os.path.join(out, "cornell_box.vtp"))
    write(light(), os.path.join(out, "cornell_light.vtp"))
    write(trajectory(), os.path.join(out, "cornell_trajectory.vtp"))
    print(f"orientation checked for {len(checked)} polygons, flipped {len(flipped)}"
          + (": " + ", ".join(flipped) if flipped else ""))


if __name__ == "__main__":
    main()
