#!/usr/bin/python3
"""Mesh bias: every face's mean radiosity at the default patch size against a fine mesh.

For the public CornellBox-Original (Data/CornellBox-Original.obj, its light where the file
puts it) and the paper room (the command line's built-in Cornell box, its light at the
paper's middle position), one frame each, the command line solves S seeds at the default patch size and S
at a quarter of it (16 times the patches). A face is the cells of one plane and one
reflectance. For every face it prints the area-weighted mean radiosity (sum of the RGB
channels) on both meshes, their relative difference and that difference's standard error
from the spread over seeds, and then the worst face. The target (issue "Accuracy you can
see", part 4) is every face within 1% of the fine mesh.

    /usr/bin/python3 Benchmarks/mesh_bias.py [--cli build/bin/moving-light-radiosity]
        [--paths 8000000] [--seeds 4] [--threads 0] [--output output/mesh-bias]

It writes results.json to the output folder.
"""
import argparse
import collections
import json
import math
import os
import subprocess
import sys

from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

SCENES = {
    "CornellBox-Original": ["--scene", os.path.join(ROOT, "Data", "CornellBox-Original.obj"),
                            "--light-material", "light", "--from", "0,1.9641,0",
                            "--to", "0,1.9641,0", "--frames", "1"],
    # The paper's middle frame (frame 15 of Data/cornell_trajectory.vtp).
    "paper room": ["--from", "0.28345,0.5478,0.28571", "--to", "0.28345,0.5478,0.28571",
                   "--frames", "1"],
}


def field(data, name):
    array = data.GetFieldData().GetArray(name)
    return array.GetValue(0) if array else None


def read(path):
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def faces(grid):
    """{(normal, offset, reflectance): (mean radiosity, area)} over the cells of grid: cells
    of one reflectance whose normals agree to a tenth and whose planes lie within 1% of the
    scene's diagonal of each other (the OBJ's left wall is not quite planar)."""
    cells = grid.GetCellData()
    radiosity, reflectance = cells.GetArray("Radiosity"), cells.GetArray("Reflectance")
    bounds = grid.GetBounds()
    diagonal = math.sqrt(sum((bounds[2 * i + 1] - bounds[2 * i]) ** 2 for i in range(3)))
    groups = collections.defaultdict(list)
    for c in range(grid.GetNumberOfCells()):
        points = grid.GetCell(c).GetPoints()
        p = [points.GetPoint(i) for i in range(3)]
        u = [p[1][i] - p[0][i] for i in range(3)]
        v = [p[2][i] - p[0][i] for i in range(3)]
        n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
        length = math.sqrt(sum(x * x for x in n))
        if length == 0:
            continue
        n = [x / length for x in n]
        key = (tuple(round(x, 1) + 0.0 for x in n),
               tuple(round(x, 3) for x in reflectance.GetTuple3(c)))
        offset = sum(n[i] * p[0][i] for i in range(3)) / diagonal
        groups[key].append((offset, length / 2, sum(radiosity.GetTuple3(c))))
    result = {}
    for (normal, rho), cells in groups.items():
        cells.sort()
        start = 0
        for i in range(1, len(cells) + 1):
            if i == len(cells) or cells[i][0] - cells[i - 1][0] > 0.01:
                face = cells[start:i]
                area = sum(a for _, a, _ in face)
                middle = round((face[0][0] + face[-1][0]) / 2, 2) + 0.0
                result[(normal, middle, rho)] = (sum(a * b for _, a, b in face) / area, area)
                start = i
    return result


def solve(cli, arguments, seed, paths, threads, patch_size, output):
    command = [cli] + arguments + ["--paths", str(paths), "--seed", str(seed),
                                   "--threads", str(threads), "--output", output + ".pvd"]
    if patch_size:
        command += ["--patch-size", repr(patch_size)]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return read(output + "_0000.vtu")


def mean_and_error(values):
    m = sum(values) / len(values)
    if len(values) < 2:
        return m, float("nan")
    variance = sum((v - m) ** 2 for v in values) / (len(values) - 1)
    return m, math.sqrt(variance / len(values))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cli", default=os.path.join(ROOT, "build", "bin", "moving-light-radiosity"))
    parser.add_argument("--paths", type=int, default=8000000)
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--output", default="output/mesh-bias")
    args = parser.parse_args()
    if args.seeds < 2:
        parser.error("--seeds must be at least 2: the standard errors come from their spread")
    os.makedirs(args.output, exist_ok=True)
    results = {}
    for name, arguments in SCENES.items():
        runs = {"default": [], "fine": []}
        edge = None
        for seed in range(1, args.seeds + 1):
            grid = solve(args.cli, arguments, seed, args.paths, args.threads, None,
                         os.path.join(args.output, "default"))
            edge = field(grid, "PatchEdgeLength")
            patches = field(grid, "Patches")
            runs["default"].append(faces(grid))
            fine = solve(args.cli, arguments, seed + 1000, args.paths, args.threads, edge / 4,
                         os.path.join(args.output, "fine"))
            fine_patches = field(fine, "Patches")
            runs["fine"].append(faces(fine))
        total = sum(a for _, a in runs["default"][0].values())
        rows = []
        for key, (_, area) in runs["default"][0].items():
            if area < 0.005 * total or any(key not in r for r in runs["fine"]):
                continue  # slivers of a rounding boundary
            a, sa = mean_and_error([r[key][0] for r in runs["default"]])
            b, sb = mean_and_error([r[key][0] for r in runs["fine"]])
            if b <= 0:
                continue
            difference = a / b - 1
            error = math.hypot(sa / a, sb / b) if a > 0 else float("nan")
            rows.append({"normal": key[0], "offset": key[1], "reflectance": key[2], "area": area,
                         "default": a, "fine": b, "difference": difference, "stdError": error})
        rows.sort(key=lambda r: -abs(r["difference"]))
        print(f"\n{name}: {args.seeds} seeds x {args.paths} paths, default patch edge {edge:.4g} "
              f"({patches} patches), fine {edge / 4:.4g} ({fine_patches} patches)")
        print(f"{'difference':>11} {'std err':>8} {'area':>8} {'default':>9} {'fine':>9}  face "
              "(normal, offset, reflectance)")
        for r in rows:
            print(f"{100 * r['difference']:+10.2f}% {100 * r['stdError']:7.2f}% {r['area']:8.4f} "
                  f"{r['default']:9.4f} {r['fine']:9.4f}  {r['normal']} {r['offset']} "
                  f"{r['reflectance']}")
        worst = rows[0]
        print(f"worst face: {100 * worst['difference']:+.2f}% (standard error "
              f"{100 * worst['stdError']:.2f}%), target within 1%")
        results[name] = {"seeds": args.seeds, "paths": args.paths, "patchEdge": edge,
                         "patches": patches, "finePatches": fine_patches, "faces": rows}
    with open(os.path.join(args.output, "results.json"), "w") as f:
        json.dump(results, f, indent=1)
    print(f"\nwrote {os.path.join(args.output, 'results.json')}")


if __name__ == "__main__":
    sys.exit(main())
