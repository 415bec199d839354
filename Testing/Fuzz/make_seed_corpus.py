#!/usr/bin/python3
"""Writes the seed corpus of the fuzz targets (Testing/Fuzz/corpus/{solve,readers}/).

solve:   byte strings that FuzzSolve.cxx decodes into small valid scenes (boxes, a triangle,
         an L-shaped pair of walls) with a light, a trajectory and options; the fuzzer mutates
         them into everything else.
readers: a first byte choosing the extension (0 .vtp, 1 .obj, 2 .ply, 3 .stl, 4 .vtu, 5 .vtk,
         6 .ies, 7 .ldt, 8 .gltf, 9 .glb, 10 .epw, as in FuzzReaders.cxx), then a small file of
         that format: a box with a cell array Reflectance, in every encoding the writers offer
         (ASCII, binary, appended, zlib); photometric files of every symmetry each format has,
         and a few malformed ones; a whole year of weather (EPW, its lines cut after the
         diffuse horizontal irradiance) and weather files cut short or wrong in one field.

Run with Debian's Python (VTK from python3-paraview): /usr/bin/python3 make_seed_corpus.py
"""
import os
import struct
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))


# --- solve: the encoding FuzzSolve.cxx decodes --------------------------------------------
def coordinate(v):
    kind = round((v + 2.0) * 4.0)
    assert 0 <= kind <= 16 and abs(kind / 4.0 - 2.0 - v) < 1e-12, v
    return bytes([kind])


def solve_input(points, polygons, light, frames, flags=0, patches=None, edge_index=None,
                paths=400, gathering=64, survival=64, cancel_after=0, memory=31):
    out = bytearray([flags, len(points) - 3])
    for p in points:
        out += b"".join(coordinate(c) for c in p)
    out += bytes([len(polygons) - 1])
    for polygon, grey in polygons:
        out += bytes([len(polygon)])
        for v in polygon:
            out += bytes([0, v])
        out += bytes([round(grey * 20)])  # kind < 200: grey (kind % 20) / 20
    out += bytes([len(light) - 1])
    for z, corners in light:
        out += coordinate(z) + bytes([len(corners) - 2])
        for x, y in corners:
            out += coordinate(x) + coordinate(y)
    out += bytes([0, 0])  # power 100 in every channel
    out += bytes([{0: 0, 1: 16, 2: 17, 3: 8}[len(frames)]])  # frame count, as decoded
    for t in frames:
        out += b"".join(coordinate(c) for c in t)
    if patches is not None:
        out += bytes([0]) + struct.pack("<H", patches)
    else:
        out += bytes([200, edge_index])
    out += bytes([0])  # sharp edge angle 30
    out += struct.pack("<H", paths) + bytes([gathering, survival, 7, 0, memory, cancel_after])
    return bytes(out)


BOX = [(x, y, z) for z in (-1, 1) for y in (-1, 1) for x in (-1, 1)]
# Quads of the box [-1,1]^3, normals out (corner index = x + 2y + 4z, bits for +1).
BOX_FACES = [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]]
LIGHT_DOWN = [(0.75, [(-0.25, -0.25), (-0.25, 0.25), (0.25, 0.25), (0.25, -0.25)])]


def solve_seeds():
    walls = [(face, 0.5 + 0.05 * i) for i, face in enumerate(BOX_FACES)]
    inward = [(list(reversed(face)), grey) for face, grey in walls]
    frames = [(0, 0, 0), (0.25, 0.25, 0)]
    yield "box_cgal", solve_input(BOX, inward, LIGHT_DOWN, frames, patches=120)
    yield "box_refine_only", solve_input(BOX, inward, LIGHT_DOWN, frames, flags=0x01, edge_index=7)
    yield "box_outward_classic_one_sided", solve_input(
        BOX, walls, LIGHT_DOWN, frames, flags=0x02 | 0x04 | 0x08, patches=60)
    yield "box_cancelled", solve_input(BOX, inward, LIGHT_DOWN, frames, flags=0x40, patches=200,
                                       cancel_after=5)
    yield "one_triangle", solve_input([(-1, -1, -1), (1, -1, -1), (-1, 1, -1)],
                                      [([0, 1, 2], 0.5)], LIGHT_DOWN, [(0, 0, 0)], edge_index=6)
    l_shape = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1), (-1, 1, 1), (1, 1, 1)]
    yield "l_shaped_walls", solve_input(l_shape, [([0, 1, 2, 3], 0.7), ([3, 2, 5, 4], 0.3)],
                                        LIGHT_DOWN, frames + [(0, -0.5, 0)], patches=80)
    concave = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (0, 0, -1), (-1, 1, -1)]
    yield "concave_polygon", solve_input(concave, [([0, 1, 2, 3, 4], 0.6)], LIGHT_DOWN,
                                         frames, edge_index=5, gathering=0)


# --- readers: small files in every format and encoding the command line reads -------------
def box_polydata():
    from vtkmodules.vtkCommonCore import vtkFloatArray, vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
    points = vtkPoints()
    for p in BOX:
        points.InsertNextPoint(*p)
    cells = vtkCellArray()
    for face in BOX_FACES:
        cells.InsertNextCell(4, face)
    rho = vtkFloatArray()
    rho.SetName("Reflectance")
    rho.SetNumberOfComponents(3)
    for i in range(len(BOX_FACES)):
        rho.InsertNextTuple3(0.5, 0.1 * i, 0.3)
    box = vtkPolyData()
    box.SetPoints(points)
    box.SetPolys(cells)
    box.GetCellData().AddArray(rho)
    return box


def reader_seeds():
    from vtkmodules.vtkFiltersCore import vtkTriangleFilter
    from vtkmodules.vtkIOGeometry import vtkOBJWriter, vtkSTLWriter
    from vtkmodules.vtkIOLegacy import vtkPolyDataWriter, vtkUnstructuredGridWriter
    from vtkmodules.vtkIOPLY import vtkPLYWriter
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter, vtkXMLUnstructuredGridWriter
    from vtkmodules.vtkFiltersCore import vtkAppendFilter

    box = box_polydata()
    triangles = vtkTriangleFilter()
    triangles.SetInputData(box)
    triangles.Update()
    grid = vtkAppendFilter()
    grid.SetInputData(box)
    grid.Update()

    def written(writer, data, setup=None, extension=".file"):
        with tempfile.TemporaryDirectory() as directory:
            path = os.path.join(directory, "file" + extension)
            writer.SetInputData(data)
            writer.SetFileName(path)
            if setup:
                setup(writer)
            assert writer.Write()
            with open(path, "rb") as f:
                return f.read()

    def xml(mode, compressed):
        def setup(w):
            getattr(w, "SetDataModeTo" + mode)()
            if mode == "Appended":
                w.EncodeAppendedDataOff()
            if compressed:
                w.SetCompressorTypeToZLib()
            else:
                w.SetCompressorTypeToNone()
        return setup

    for mode in ("Ascii", "Binary", "Appended"):
        for compressed in (False, True):
            if mode == "Ascii" and compressed:
                continue
            name = mode.lower() + ("_zlib" if compressed else "")
            yield "vtp_" + name, 0, written(vtkXMLPolyDataWriter(), box, xml(mode, compressed))
            yield "vtu_" + name, 4, written(vtkXMLUnstructuredGridWriter(), grid.GetOutput(),
                                            xml(mode, compressed))
    yield "obj", 1, written(vtkOBJWriter(), box)
    yield "obj_handwritten", 1, (b"# two quads and a triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0\n"
                                 b"v 0 1 0\nv 0 1 1\nvn 0 0 1\nvt 0 0\n"
                                 b"f 1 2 3 4\nf 4/1 3/1 5/1\nf -1 -2 -3\nl 1 2\n")
    for binary in (False, True):
        suffix = "binary" if binary else "ascii"

        def ply(w, binary=binary):
            (w.SetFileTypeToBinary if binary else w.SetFileTypeToASCII)()
        yield "ply_" + suffix, 2, written(vtkPLYWriter(), box, ply, ".ply")

        def stl(w, binary=binary):
            (w.SetFileTypeToBinary if binary else w.SetFileTypeToASCII)()
        yield "stl_" + suffix, 3, written(vtkSTLWriter(), triangles.GetOutput(), stl, ".stl")

        def legacy(w, binary=binary):
            (w.SetFileTypeToBinary if binary else w.SetFileTypeToASCII)()
        yield "vtk_polydata_" + suffix, 5, written(vtkPolyDataWriter(), box, legacy)
        yield "vtk_grid_" + suffix, 5, written(vtkUnstructuredGridWriter(), grid.GetOutput(),
                                               legacy)
    # Triangle strips as scanned models store them (Stanford's igea.ply): one list, -1 ending
    # each strip, with repeated indices joining strips.
    corners = [(0, 0, 0), (0, 1, 0), (1, 0, 0), (1, 1, 0), (2, 0, 0), (2, 1, 0)]
    strips = [0, 1, 2, 3, -1, 2, 3, 3, 4, 4, 5]

    def strip_header(form):
        return (f"ply\nformat {form} 1.0\nelement vertex {len(corners)}\nproperty float x\n"
                "property float y\nproperty float z\nelement tristrips 1\n"
                "property list int int vertex_indices\nend_header\n").encode()
    yield "ply_tristrips_ascii", 2, (strip_header("ascii") + "".join(
        f"{x} {y} {z}\n" for x, y, z in corners).encode() +
        (" ".join(str(i) for i in [len(strips)] + strips) + "\n").encode())
    yield "ply_tristrips_binary", 2, (strip_header("binary_big_endian") + b"".join(
        struct.pack(">3f", *c) for c in corners) + struct.pack(f">{len(strips) + 1}i",
                                                               len(strips), *strips))


# --- readers: photometric files (IES LM-63 types C, B and A, TILT=INCLUDE, EULUMDAT) ----------
def ies_text(vertical, horizontal, candela, header="IESNA:LM-63-2002", tilt="TILT=NONE",
             units=2, lamp_line=None):
    lines = [header, "[TEST] seed", "[MANUFAC] MovingLightRadiosity", tilt]
    lines.append(lamp_line or f"1 -1 1 {len(vertical)} {len(horizontal)} 1 {units} 0.5 0.5 0")
    lines.append("1 1 30")
    lines.append(" ".join(f"{a:g}" for a in vertical))
    lines.append(" ".join(f"{a:g}" for a in horizontal))
    for row in candela:
        lines.append(" ".join(f"{v:g}" for v in row))
    return ("\n".join(lines) + "\n").encode()


def ldt_text(isym, mc, gammas, stored_rows, flux=1000):
    dc = 360 / mc
    lines = ["Seed", "1", str(isym), str(mc), f"{dc:g}", str(len(gammas)),
             f"{gammas[1] - gammas[0]:g}", "report", "luminaire", "number", "seed.ldt",
             "2026-12-01", "600", "0", "80", "500", "300", "0", "0", "0", "0", "100", "80", "1",
             "0", "1", "1", "LED", f"{flux:g}", "3000", "1B", "40"]
    lines += ["0.5"] * 10
    lines += [f"{i * dc:g}" for i in range(mc)]
    lines += [f"{g:g}" for g in gammas]
    for row in stored_rows:
        lines += [f"{v:g}" for v in row]
    return ("\r\n".join(lines) + "\r\n").encode()


def photometric_seeds():
    import math
    vertical = [0, 22.5, 45, 67.5, 90]

    def row(c):
        return [round(100 * math.cos(math.radians(g)) * (1.2 + math.cos(math.radians(c))), 3)
                for g in vertical]

    for name, planes in (("rotational", [0]), ("quadrant", [0, 45, 90]),
                         ("bilateral", [0, 90, 180]), ("full", [0, 90, 180, 270, 360]),
                         ("ninety_to_270", [90, 180, 270])):
        yield "ies_" + name, 6, ies_text(vertical, planes, [row(c) for c in planes])
    yield "ies_1995_uplight_feet", 6, ies_text([90, 135, 180], [0], [[10, 50, 80]],
                                                header="IESNA:LM-63-1995", units=1)
    yield "ies_1986_no_header", 6, ies_text(vertical, [0], [row(0)], header="an old file")
    yield "ies_2019_tilt_include", 6, ies_text(
        vertical, [0], [row(0)], header="IES:LM-63-2019",
        tilt="TILT=INCLUDE\n1\n3\n0 45 90\n1 0.95 0.9")
    good = ies_text(vertical, [0, 90, 180], [row(c) for c in (0, 90, 180)])
    yield "ies_truncated", 6, good[:len(good) - 12]
    yield "ies_text_in_number", 6, good.replace(b"1 1 30", b"1 one 30")
    yield "ies_huge_counts", 6, ies_text(vertical, [0], [row(0)],
                                         lamp_line="1 -1 1 9999 9999 1 2 0 0 0")
    yield "ies_tilt_file", 6, ies_text(vertical, [0], [row(0)], tilt="TILT=lamp.tlt")
    # Type B (photometric type 2): vertical angles -90 to 90, laterally symmetric (H 0 to 90)
    # and full (H -90 to 90).
    b_vertical = [-90, -45, 0, 45, 90]
    for name, planes in (("type_b_lateral", [0, 45, 90]), ("type_b_full", [-90, 0, 90])):
        yield "ies_" + name, 6, ies_text(
            b_vertical, planes, [[round(50 + 40 * math.cos(math.radians(v)), 3)
                                  for v in b_vertical] for _ in planes],
            lamp_line=f"1 -1 1 {len(b_vertical)} {len(planes)} 2 2 0.5 0.5 0")

    # Type A (photometric type 3): planes through the vertical axis, H clockwise, V from -90.
    for name, planes in (("type_a_lateral", [0, 45, 90]), ("type_a_full", [-90, 0, 90])):
        yield "ies_" + name, 6, ies_text(
            b_vertical, planes, [[round(60 + 30 * math.cos(math.radians(v)), 3)
                                  for v in b_vertical] for _ in planes],
            lamp_line=f"1 -1 1 {len(b_vertical)} {len(planes)} 3 2 0.5 0.5 0")
    # TILT=INCLUDE tables that vary, for a horizontal lamp (geometry 2) and in feet with a
    # round opening; a tilt block whose angles descend; a vertical cylinder's opening.
    yield "ies_tilt_geometry2", 6, ies_text(
        vertical, [0, 90, 180], [row(c) for c in (0, 90, 180)],
        tilt="TILT=INCLUDE\n2\n7\n0 15 30 45 60 75 90\n1 0.98 0.94 0.9 0.85 0.8 0.76")
    yield "ies_tilt_round_feet", 6, ies_text(
        vertical, [0], [row(0)], tilt="TILT=INCLUDE\n3\n3\n-90 0 90\n0.8 1 0.8", units=1,
        lamp_line=f"1 -1 1 {len(vertical)} 1 1 1 -0.5 -0.5 0")
    yield "ies_tilt_descending", 6, ies_text(
        vertical, [0], [row(0)], tilt="TILT=INCLUDE\n1\n3\n0 45 30\n1 1 1")
    yield "ies_vertical_cylinder", 6, ies_text(
        vertical, [0], [row(0)], lamp_line=f"1 -1 1 {len(vertical)} 1 1 2 -0.2 -0.2 0.3")
    # Finite candela whose flux is beyond MaximumLightPower (1e30 lm): refused.
    yield "ies_flux_beyond_the_bound", 6, ies_text(vertical, [0], [[1e300] * len(vertical)])

    gammas = [0, 30, 60, 90, 120, 150, 180]

    def ldt_row(c):
        return [round(max(0.0, 200 * math.cos(math.radians(g))) *
                      (1.2 + math.sin(math.radians(c))), 3) for g in gammas]

    for isym, planes in ((0, [0, 90, 180, 270]), (1, [0]), (2, [0, 90, 180]),
                         (3, [270, 0, 90]), (4, [0, 90])):
        yield f"ldt_isym{isym}", 7, ldt_text(isym, 4, gammas, [ldt_row(c) for c in planes])
    good = ldt_text(0, 4, gammas, [ldt_row(c) for c in (0, 90, 180, 270)])
    yield "ldt_truncated", 7, good[:len(good) // 2]
    yield "ldt_negative_intensity", 7, good.replace(b"\r\n240\r\n", b"\r\n-240\r\n", 1)
    yield "ldt_bad_symmetry", 7, good.replace(b"Seed\r\n1\r\n0\r\n", b"Seed\r\n1\r\n7\r\n", 1)
    yield "ldt_negative_flux", 7, good.replace(b"\r\nLED\r\n1000\r\n", b"\r\nLED\r\n-1000\r\n", 1)


def gltf_seeds():
    """A triangle with a material as .gltf (its buffer a data: URI) and as .glb (a BIN chunk)."""
    import base64
    import json
    data = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<3H", 0, 1, 2) + b"\0\0"

    def document(buffer):
        return {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
                "nodes": [{"mesh": 0, "translation": [0, 0, 1]}],
                "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.6, 0.7, 1]},
                               "emissiveFactor": [0.1, 0.1, 0.1]}],
                "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1,
                                            "material": 0}]}],
                "buffers": [buffer],
                "bufferViews": [{"buffer": 0, "byteLength": 36},
                                {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
                "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3,
                               "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                              {"bufferView": 1, "componentType": 5123, "count": 3,
                               "type": "SCALAR"}]}
    uri = "data:application/octet-stream;base64," + base64.b64encode(data).decode()
    yield "gltf_triangle", 8, json.dumps(
        document({"byteLength": len(data), "uri": uri})).encode()
    text = json.dumps(document({"byteLength": len(data)})).encode()
    text += b" " * (-len(text) % 4)
    body = (struct.pack("<I4s", len(text), b"JSON") + text +
            struct.pack("<I4s", len(data), b"BIN\0") + data)
    yield "glb_triangle", 9, struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body
    # The same triangle through the parts that shape geometry: positions given sparsely over
    # zeros, a morph target at the mesh's weight, a mirroring node, a punctual light.
    extra = data + bytes([0, 1, 2, 0]) + struct.pack("<9f", 0, 0, 1, 0, 0, 1, 0, 0, 1)
    shaped = document({"byteLength": len(extra), "uri": "data:application/octet-stream;base64,"
                       + base64.b64encode(extra).decode()})
    shaped["bufferViews"] += [{"buffer": 0, "byteOffset": 44, "byteLength": 3},
                              {"buffer": 0, "byteOffset": 48, "byteLength": 36}]
    shaped["accessors"][0] = {"componentType": 5126, "count": 3, "type": "VEC3",
                              "sparse": {"count": 3,
                                         "indices": {"bufferView": 2, "componentType": 5121},
                                         "values": {"bufferView": 0}}}
    shaped["accessors"].append({"bufferView": 3, "componentType": 5126, "count": 3,
                                "type": "VEC3"})
    shaped["meshes"][0]["primitives"][0]["targets"] = [{"POSITION": 2}]
    shaped["meshes"][0]["weights"] = [0.5]
    shaped["nodes"][0]["scale"] = [1, 1, -1]
    shaped["extensionsUsed"] = ["KHR_lights_punctual"]
    shaped["extensions"] = {"KHR_lights_punctual": {"lights": [{"type": "point"}]}}
    yield "gltf_sparse_morph_mirrored", 8, json.dumps(shaped).encode()


EPW_HEADER = ("LOCATION,Paris,IDF,FRA,seed,071560,48.85,2.35,1.0,35.0\n"
              "DESIGN CONDITIONS,0\nTYPICAL/EXTREME PERIODS,0\nGROUND TEMPERATURES,0\n"
              "HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0\nCOMMENTS 1,seed\nCOMMENTS 2,seed\n"
              "DATA PERIODS,1,1,Data,Sunday,1/1,12/31\n")


def epw_hours(leap=False, count=None):
    """Hourly lines of a year to field 16: a sun from 6 to 18 with DNI 600 and DHI 100."""
    days = [31, 29 if leap else 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31]
    lines = []
    for month, n in enumerate(days, start=1):
        for day in range(1, n + 1):
            for hour in range(1, 25):
                up = 7 <= hour <= 18
                lines.append("%d,%d,%d,%d,60,*9,10,5,70,101325,0,0,300,%d,%d,%d\n" % (
                    2024 if leap else 2023, month, day, hour, 400 if up else 0,
                    600 if up else 0, 100 if up else 0))
    return lines[:count] if count is not None else lines


def weather_seeds():
    yield "epw_year", 10, (EPW_HEADER + "".join(epw_hours())).encode()
    yield "epw_header_only", 10, EPW_HEADER.encode()
    yield "epw_two_days", 10, (EPW_HEADER + "".join(epw_hours(count=48))).encode()
    broken = epw_hours(count=48)
    broken[30] = broken[30].replace(",600,", ",-600,")
    yield "epw_negative_dni", 10, (EPW_HEADER + "".join(broken)).encode()
    yield "epw_no_location", 10, EPW_HEADER.replace("LOCATION", "PLACE").encode()


def main():
    for target, seeds in (("solve", ((n, b) for n, b in solve_seeds())),
                          ("readers", ((n, bytes([k]) + b) for seeds in
                                       (reader_seeds(), photometric_seeds(), gltf_seeds(),
                                        weather_seeds())
                                       for n, k, b in seeds))):
        directory = os.path.join(HERE, "corpus", target)
        os.makedirs(directory, exist_ok=True)
        for name, data in seeds:
            with open(os.path.join(directory, name), "wb") as f:
                f.write(data)
            print(f"corpus/{target}/{name}: {len(data)} bytes")


if __name__ == "__main__":
    main()
