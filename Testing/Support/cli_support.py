"""What the command-line test modules share: where the executable and the data are, a fast
solve's options, running the program, and writing inputs.

ctest sets MLR_CLI (the executable) and MLR_DATA_DIR (Data/); the defaults fit a build in build/.
"""
import os
import subprocess
import time

from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter

HERE = os.path.dirname(os.path.abspath(__file__))
CLI = os.path.abspath(os.environ.get("MLR_CLI", os.path.join(
    HERE, os.pardir, os.pardir, "build", "bin", "moving-light-radiosity")))
DATA = os.path.abspath(os.environ.get("MLR_DATA_DIR",
                                     os.path.join(HERE, os.pardir, os.pardir, "Data")))
SCENE = os.path.join(DATA, "cornell_box.vtp")
LIGHT = os.path.join(DATA, "cornell_light.vtp")
FAST = ["--paths", "20000", "--patch-size", "0.08"]


def run(args, cwd, env=None, timeout=300):
    return subprocess.run([CLI] + args, cwd=cwd, capture_output=True, text=True,
                          timeout=timeout, env=env)


def lines_until(process, marker, seconds):
    """The lines `process` prints on stdout up to the first that holds `marker` (or its end, or
    `seconds`): a test that interrupts a run at a known point reads them first."""
    seen = []
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        line = process.stdout.readline()
        if not line:
            break
        seen.append(line)
        if marker in line:
            break
    return seen


def all_files(directory):
    return sorted(os.path.relpath(os.path.join(root, name), directory)
                  for root, _, names in os.walk(directory) for name in names)


def write_polydata(data, path, compressed=None):
    """compressed: None keeps VTK's default encoding, True appends zlib-compressed data,
    False writes without a compressor."""
    writer = vtkXMLPolyDataWriter()
    writer.SetInputData(data)
    writer.SetFileName(str(path))
    if compressed:
        writer.SetDataModeToAppended()
        writer.SetCompressorTypeToZLib()
    elif compressed is False:
        writer.SetCompressorTypeToNone()
    assert writer.Write()
