"""Examples/cornell_box_animation.py runs as the README says (pvpython on an X display) on the
shipped Cornell box, with few paths and small pictures: it writes one lit PNG and one .vtu per
trajectory position and a .pvd listing their times."""
import os
import shutil
import signal
import subprocess
import time
import xml.etree.ElementTree as ElementTree

import pytest

from xvfb_display import virtual_display

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
POSITIONS = 30  # Data/cornell_trajectory.vtp


def run_example(script, output, options):
    """Runs Examples/<script> with pvpython on a private X display (the README runs it under an
    X server too; a private one keeps parallel tests apart) and the built plugin, and returns
    its report once it exited 0."""
    if not shutil.which("Xvfb"):
        pytest.skip("Xvfb is not installed")
    plugin = os.environ.get("MLR_PLUGIN")
    assert plugin and os.path.isfile(plugin), f"set MLR_PLUGIN to the built plugin ({plugin!r})"
    env = {k: v for k, v in os.environ.items() if k not in ("PV_PLUGIN_PATH", "PYTHONPATH")}
    with virtual_display() as display:
        run = subprocess.run(
            [os.environ.get("MLR_PVPYTHON", "pvpython"), os.path.join(ROOT, "Examples", script),
             "--plugin", plugin, "--output", str(output)] + [str(o) for o in options],
            capture_output=True, text=True, timeout=300, env=dict(env, DISPLAY=display))
    report = f"exit code {run.returncode}\n--- stdout\n{run.stdout}\n--- stderr\n{run.stderr}"
    assert run.returncode == 0, report
    return report


def test_example_writes_the_animation(tmp_path):
    output = tmp_path / "animation"
    report = run_example("cornell_box_animation.py", output, ["--paths", "20000", "--size", "128"])

    pvd = output / "cornell.pvd"
    assert pvd.is_file(), report
    entries = [(float(e.get("timestep")), e.get("file"))
               for e in ElementTree.parse(pvd).getroot().iter("DataSet")]
    assert [t for t, _ in entries] == [float(i) for i in range(POSITIONS)], entries
    assert all((output / f).is_file() and f.endswith(".vtu") for _, f in entries), entries

    pictures = sorted((output / "png").glob("frame_*.png"))
    assert [p.name for p in pictures] == [f"frame_{i:04d}.png" for i in range(POSITIONS)], pictures
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOImage import vtkPNGReader
    for picture in (pictures[0], pictures[-1]):
        reader = vtkPNGReader()
        reader.SetFileName(str(picture))
        reader.Update()
        pixels = vtk_to_numpy(reader.GetOutput().GetPointData().GetScalars())[:, :3]
        lit = (pixels.max(axis=1) > 30).mean()
        assert lit > 0.5, f"{picture.name}: only {100 * lit:.0f}% of the picture is lit"
        # The red and the green wall: a colour picture, not a grey or a colour-mapped one.
        red = ((pixels[:, 0] > 1.5 * pixels[:, 1]) & (pixels[:, 0] > 40)).mean()
        green = ((pixels[:, 1] > 1.5 * pixels[:, 0]) & (pixels[:, 1] > 40)).mean()
        assert red > 0.05 and green > 0.05, f"{picture.name}: red {red:.2f}, green {green:.2f} of the picture"


def session_processes(session):
    """The processes left in session `session` (their pids)."""
    left = []
    for entry in os.listdir("/proc"):
        try:
            with open(f"/proc/{entry}/stat") as stat:
                fields = stat.read().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue  # not a process, or it ended meanwhile
        if fields[0] != "Z" and int(fields[3]) == session:
            left.append(int(entry))
    return left


def test_example_under_pvbatch_without_a_display_ends(tmp_path):
    """Under pvbatch without DISPLAY the example starts its own Xvfb. It used to stop it from
    Python's exit handlers, before pvbatch's ParaView closed its X connection: pvbatch then
    failed on an X I/O error, aborted on a double free and hung for ever, after writing
    everything. It exits 0, and nothing it started outlives it."""
    if not shutil.which("Xvfb"):
        pytest.skip("Xvfb is not installed")
    pvbatch = os.environ.get("MLR_PVBATCH") or shutil.which("pvbatch")
    if not pvbatch:
        pytest.skip("pvbatch is not installed")
    plugin = os.environ.get("MLR_PLUGIN")
    assert plugin and os.path.isfile(plugin), f"set MLR_PLUGIN to the built plugin ({plugin!r})"
    env = {k: v for k, v in os.environ.items()
           if k not in ("PV_PLUGIN_PATH", "PYTHONPATH", "DISPLAY")}
    output = tmp_path / "animation"
    process = subprocess.Popen(
        [pvbatch, "--force-offscreen-rendering",
         os.path.join(ROOT, "Examples", "cornell_box_animation.py"), "--plugin", plugin,
         "--output", str(output), "--paths", "20000", "--size", "64"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env,
        start_new_session=True)
    try:
        log, _ = process.communicate(timeout=240)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
    assert process.returncode == 0, log
    assert len(list((output / "png").glob("frame_*.png"))) == POSITIONS, log
    # The kernel stops the Xvfb when pvbatch ends: give it a moment.
    for _ in range(50):
        if not session_processes(process.pid):
            break
        time.sleep(0.1)
    assert session_processes(process.pid) == [], log


def test_sun_example_writes_a_day(tmp_path):
    """Examples/sun_town_block.py: Sources > Sun Path into Moving Light Radiosity with Light
    Type Directional, every 2 hours from 05:00 to 21:00 summer time in Paris on 21 June 2024.
    The series' times are the clock hours; 05:00 is before sunrise (05:47), so that step is
    dark, and 13:00 (near solar noon) is lit, with the ground's direct light at the level of
    rho E sin(elevation)."""
    output = tmp_path / "sun"
    run_example("sun_town_block.py", output, ["--paths", "200000", "--step", "120", "--size", "96"])
    entries = [(float(e.get("timestep")), e.get("file"))
               for e in ElementTree.parse(output / "town.pvd").getroot().iter("DataSet")]
    assert [t for t, _ in entries] == [5.0 + 2 * i for i in range(9)], entries
    assert len(sorted((output / "png").glob("frame_*.png"))) == 9

    import math
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkFiltersVerdict import vtkCellSizeFilter
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    def frame(index):
        reader = vtkXMLUnstructuredGridReader()
        reader.SetFileName(str(output / entries[index][1]))
        sizes = vtkCellSizeFilter()
        sizes.SetInputConnection(reader.GetOutputPort())
        sizes.Update()
        return sizes.GetOutput()

    night = frame(0)
    assert night.GetFieldData().GetArray("SunElevation").GetValue(0) < 0
    assert vtk_to_numpy(night.GetCellData().GetArray("Radiosity")).max() == 0.0

    noon = frame(4)  # 13:00
    elevation = noon.GetFieldData().GetArray("SunElevation").GetValue(0)
    assert 60 < elevation < 66, elevation  # 90 - 48.85 + 23.44 = 64.6 at solar noon (13:58)
    # The ground's far corner (x, y > 30 m) is never shaded: rho E sin(elevation).
    centres = vtk_to_numpy(noon.GetPoints().GetData())
    cells = vtk_to_numpy(noon.GetCells().GetConnectivityArray()).reshape(-1, 3)
    corner = centres[cells].min(axis=1)
    on_ground = (centres[cells][:, :, 2].max(axis=1) < 1e-9) & (corner[:, 0] > 30) & (corner[:, 1] > 30)
    area = vtk_to_numpy(noon.GetCellData().GetArray("Area"))[on_ground]
    direct = vtk_to_numpy(noon.GetCellData().GetArray("DirectRadiosity"))[on_ground, 0]
    expected = 0.25 * 1000 * math.sin(math.radians(elevation))
    mean = (direct * area).sum() / area.sum()
    # About 100 m^2 of the ~12,000 m^2 disc: some 1,700 first hits at 200,000 paths, so the
    # mean is good to a few percent.
    assert abs(mean - expected) < 0.1 * expected, (mean, expected)


def test_spotlight_example_pans(tmp_path):
    """Examples/panning_spotlight.py: a Trajectory with a Normal array turns the lamp 90
    degrees; the green wall (x = 0) is lit more at the start and the red wall (x = 0.556) more
    at the end, and the Light output's polygon faces each step's Normal. The lamp is a spot
    (20 degrees and a 10 degree soft edge): the wall it turns away from, more than 70 degrees
    off its axis at the first and last steps, gets no direct light at all."""
    output = tmp_path / "spotlight"
    run_example("panning_spotlight.py", output, ["--paths", "100000", "--steps", "5", "--size", "96"])
    entries = [e.get("file") for e in ElementTree.parse(output / "spotlight.pvd").getroot().iter("DataSet")]
    assert len(entries) == 5, entries

    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    def wall_direct(file):
        reader = vtkXMLUnstructuredGridReader()
        reader.SetFileName(str(output / file))
        reader.Update()
        data = reader.GetOutput()
        points = vtk_to_numpy(data.GetPoints().GetData())
        cells = vtk_to_numpy(data.GetCells().GetConnectivityArray()).reshape(-1, 3)
        x = points[cells][:, :, 0]
        direct = vtk_to_numpy(data.GetCellData().GetArray("DirectRadiosity")).sum(axis=1)
        green = direct[x.max(axis=1) < 1e-6].mean()
        red = direct[x.min(axis=1) > 0.545].mean()  # the red wall leans a little (x 0.5496 to 0.556)
        return green, red

    green0, red0 = wall_direct(entries[0])
    green4, red4 = wall_direct(entries[-1])
    assert green0 > 3 * red0 and red4 > 3 * green4, (green0, red0, green4, red4)
    assert red0 == 0 and green4 == 0 and green0 > 0 and red4 > 0, (green0, red0, green4, red4)
    assert (output / "png" / "illuminance.png").stat().st_size > 0


def test_material_scenes_example(tmp_path):
    """Examples/material_scenes.py: the Cornell box OBJ + MTL (lamp material "light") and the
    glTF room of Data/make_gltf_room.py (lamp material "panel"), each opened with the scene
    reader and lit by its own lamp moving in 4 steps. The series' times are the steps; the
    pictures are in the scenes' own colours (the Cornell box's red and green walls, the room's
    red and blue walls and green box), not grey, and the lamp moves: the first and last
    frames differ."""
    output = tmp_path / "materials"
    frames = 4
    report = run_example("material_scenes.py", output, ["--paths", "40000", "--frames", str(frames), "--size", "96"])

    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOImage import vtkPNGReader

    def pixels(picture):
        reader = vtkPNGReader()
        reader.SetFileName(str(picture))
        reader.Update()
        return vtk_to_numpy(reader.GetOutput().GetPointData().GetScalars())[:, :3].astype(int)

    def share(p, channel, over):
        """The share of the picture where `channel` is bright and 1.5 times each of `over`."""
        mask = p[:, channel] > 40
        for other in over:
            mask &= p[:, channel] > 1.5 * p[:, other]
        return mask.mean()

    R, G, B = 0, 1, 2
    # name: the colours each picture must show, as (channel, channels it must exceed)
    expected = {"cornell": {"red wall": (R, (G, B)), "green wall": (G, (R, B))},
                "room": {"red wall": (R, (G, B)), "blue wall": (B, (R, G)), "green box": (G, (R, B))}}
    for name, colours in expected.items():
        pvd = output / f"{name}.pvd"
        assert pvd.is_file(), report
        entries = [(float(e.get("timestep")), e.get("file"))
                   for e in ElementTree.parse(pvd).getroot().iter("DataSet")]
        assert [t for t, _ in entries] == [float(i) for i in range(frames)], (name, entries)
        assert all((output / f).is_file() and f.endswith(".vtu") for _, f in entries), entries
        pictures = sorted((output / "png" / name).glob("frame_*.png"))
        assert [p.name for p in pictures] == [f"frame_{i:04d}.png" for i in range(frames)], pictures
        first, last = pixels(pictures[0]), pixels(pictures[-1])
        for picture, p in ((pictures[0], first), (pictures[-1], last)):
            lit = (p.max(axis=1) > 30).mean()
            assert lit > 0.4, f"{name}/{picture.name}: only {100 * lit:.0f}% of the picture is lit"
            # Grey would have R = G = B everywhere: the walls' own colours must show.
            spread = (p.max(axis=1) - p.min(axis=1) > 40).mean()
            assert spread > 0.2, f"{name}/{picture.name}: only {100 * spread:.0f}% of the picture is coloured"
            for colour, (channel, over) in colours.items():
                # A grey picture has none; the room's box, away from the lamp, shows 3% at 96 px.
                seen = share(p, channel, over)
                assert seen > 0.015, f"{name}/{picture.name}: the {colour} covers {100 * seen:.1f}% of the picture"
        assert abs(first - last).mean() > 2, f"{name}: the first and last pictures are the same: the lamp did not move"


def test_sun_example_reads_a_weather_file(tmp_path):
    """Examples/sun_town_block.py --weather: the hours 06:00 to 20:00 of 21 June from
    Data/paris_synthetic.epw, with a Perez sky. The series' times are the hours of the year
    (day 172 of 2023 starts at hour 4104); every hour is lit, by the sky at least."""
    output = tmp_path / "weather"
    run_example("sun_town_block.py", output, ["--paths", "50000", "--size", "64", "--weather"])
    entries = [(float(e.get("timestep")), e.get("file"))
               for e in ElementTree.parse(output / "town.pvd").getroot().iter("DataSet")]
    assert [t for t, _ in entries] == [171 * 24 + h for h in range(6, 20)], entries
    assert len(sorted((output / "png").glob("frame_*.png"))) == 14

    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
    for _, name in (entries[0], entries[-1]):
        reader = vtkXMLUnstructuredGridReader()
        reader.SetFileName(str(output / name))
        reader.Update()
        frame = reader.GetOutput()
        assert frame.GetFieldData().GetArray("SunElevation").GetValue(0) > 0
        assert vtk_to_numpy(frame.GetCellData().GetArray("Irradiance")).max() > 50

