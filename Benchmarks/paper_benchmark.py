#!/usr/bin/python3
"""Reproduce the paper's measurements (Sbert & Castro, Fig. 2 and section 4) on the Cornell box.

One run measures, on the shipped Cornell box remeshed to the paper's 2,686 patches / 10,744
elements, with 30 light positions on a diagonal just below the ceiling, N = 600,000 effective
paths per frame, k = 1 and lambda = 0.25:

- a reference solution of every frame (classic, 16x the paths, cached on disk);
- for classic, gathering-only reuse, shooting-only reuse and full reuse: seconds, rays by
  kind, the MSE of every frame against the reference and the flicker (Documentation/Method.md);
- the time-vs-MSE curve of the middle frame (frame 17 of 30, the paper's Fig. 2) for the four
  modes at several path counts;
- the speed-up of full reuse over classic beside the paper's eq. (4) with the measured l.

It writes results.json and CSV tables to the output folder, and, with a display (run it
under `xvfb-run -a`), side-by-side pictures of the middle frame. plot_paper.py draws the
plots from results.json. Tools/run-paper-benchmark.sh builds everything and runs both.

The filter runs through the Python package exactly as users run it, so the times are those of
the real pipeline (without the remeshing, which every mode shares).
"""
import argparse
import csv
import hashlib
import json
import os
import sys
import time

import numpy as np

from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkPolyData
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader

from movinglightradiosity import vtkMovingLightRadiosity

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.environ.get("MLR_DATA_DIR", os.path.join(HERE, os.pardir, "Data"))

# name -> (ReuseShooting, ReuseGathering)
MODES = {
    "classic": (False, False),
    "gathering reuse": (False, True),
    "shooting reuse": (True, False),
    "full reuse": (True, True),
}

# Bump when the solver's output for the same settings changes, so cached references go stale.
REFERENCE_VERSION = 2


class Config:
    """The paper's configuration, or the quick one the test suite runs."""

    def __init__(self, quick=False):
        self.quick = quick
        # 0.046 m remeshes the Cornell box into 2,686 patches, the paper's count.
        self.patch_size = 0.12 if quick else 0.046
        self.frames = 6 if quick else 30
        self.paths = 20000 if quick else 600000
        self.gathering_ratio = 1.0
        self.survival = 0.25
        self.reference_factor = 16
        self.curve_paths = [5000, 20000] if quick else [75000, 150000, 300000, 600000, 1200000]
        self.seed = 1
        self.threads = 0

    def as_dict(self):
        return dict(vars(self))


class Inputs:
    """The shipped Cornell box, light and trajectory, read once."""

    def __init__(self, frames):
        self.readers = []
        for name in ("cornell_box", "cornell_light", "cornell_trajectory"):
            reader = vtkXMLPolyDataReader()
            reader.SetFileName(os.path.join(DATA, name + ".vtp"))
            reader.Update()
            self.readers.append(reader)
        trajectory = self.readers[2].GetOutput()
        if frames > trajectory.GetNumberOfPoints():
            raise SystemExit(f"the trajectory has only {trajectory.GetNumberOfPoints()} points")
        # Fewer frames (quick mode) keep every k-th position, so that the positions still
        # span the whole diagonal.
        self.positions = [trajectory.GetPoint(i) for i in
                          np.linspace(0, trajectory.GetNumberOfPoints() - 1, frames).round().astype(int)]

    def digest(self):
        h = hashlib.sha256()
        for name in ("cornell_box", "cornell_light", "cornell_trajectory"):
            with open(os.path.join(DATA, name + ".vtp"), "rb") as f:
                h.update(f.read())
        h.update(repr(self.positions).encode())
        return h.hexdigest()[:16]


class Run:
    """One solve of the whole animation: radiosity of every frame and the statistics."""

    def __init__(self, radiosity, areas, stats, mesh=None):
        self.radiosity = radiosity  # [frames, elements, 3]
        self.areas = areas          # [elements]
        self.stats = stats
        self.mesh = mesh            # the element mesh (vtkPolyData), for pictures

    @property
    def seconds(self):
        return self.stats["SecondsSolve"]


def solve(inputs, config, paths, mode, seed=None):
    trajectory = vtkPolyData()
    points = vtkPoints()
    for p in inputs.positions:
        points.InsertNextPoint(p)
    trajectory.SetPoints(points)

    shooting, gathering = MODES[mode]
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetInputConnection(0, inputs.readers[0].GetOutputPort())
    radiosity.SetInputConnection(1, inputs.readers[1].GetOutputPort())
    radiosity.SetTrajectoryData(trajectory)
    radiosity.SetPatchSize(config.patch_size)
    radiosity.SetNumberOfPaths(paths)
    radiosity.SetGatheringRatio(config.gathering_ratio)
    radiosity.SetFirstBounceSurvival(config.survival)
    radiosity.SetReuseShooting(shooting)
    radiosity.SetReuseGathering(gathering)
    radiosity.SetSeed(config.seed if seed is None else seed)
    radiosity.SetNumberOfThreads(config.threads)
    # The paper's method as one solve: the error batches' cost per batch is not the paper's.
    radiosity.SetErrorBatches(1)

    frames = []
    for f in range(len(inputs.positions)):
        if not radiosity.UpdateTimeStep(float(f)):
            raise SystemExit(f"the filter failed on frame {f} ({mode}, {paths} paths)")
        elements = radiosity.GetOutput(0)
        frames.append(vtk_to_numpy(elements.GetCellData().GetArray("Radiosity")).copy())
    assert radiosity.GetSolveCount() == 1, "stepping through time must not solve again"
    fields = elements.GetFieldData()
    stats = {}
    for i in range(fields.GetNumberOfArrays()):
        array = fields.GetAbstractArray(i)
        if hasattr(array, "GetTuple") and array.GetNumberOfComponents() == 1:
            stats[array.GetName()] = array.GetTuple(0)[0]
    mesh = vtkPolyData()
    mesh.CopyStructure(elements)
    return Run(np.stack(frames), element_areas(elements), stats, mesh)


def element_areas(elements):
    points = vtk_to_numpy(elements.GetPoints().GetData()).astype(float)
    cells = vtk_to_numpy(elements.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    a, b, c = points[cells[:, 0]], points[cells[:, 1]], points[cells[:, 2]]
    return 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)


def mse_per_frame(run, reference):
    """Area-weighted mean over elements and channels of (B - B_ref)^2, per frame."""
    squared = ((run.radiosity - reference.radiosity) ** 2).mean(axis=2)  # [frames, elements]
    return (squared * run.areas).sum(axis=1) / run.areas.sum()


def flicker(run, reference):
    """RMS over elements (area-weighted), channels and consecutive frame pairs of
    (B[f+1] - B[f]) - (B_ref[f+1] - B_ref[f])."""
    change = np.diff(run.radiosity, axis=0) - np.diff(reference.radiosity, axis=0)
    squared = (change ** 2).mean(axis=2)
    return float(np.sqrt((squared * run.areas).sum(axis=1).mean() / run.areas.sum()))


def reference_solution(inputs, config, cache_dir):
    """Classic with reference_factor x the largest path count, cached by every input."""
    paths = config.reference_factor * max(config.paths, max(config.curve_paths))
    key = hashlib.sha256(json.dumps({
        "inputs": inputs.digest(), "patch_size": config.patch_size, "paths": paths,
        "k": config.gathering_ratio, "lambda": config.survival, "seed": 12345,
        "version": REFERENCE_VERSION}, sort_keys=True).encode()).hexdigest()[:16]
    path = os.path.join(cache_dir, f"reference-{key}.npz")
    if os.path.exists(path):
        cached = np.load(path)
        print(f"reference: cached {path} ({paths} classic paths per frame)")
        return Run(cached["radiosity"], cached["areas"], json.loads(str(cached["stats"]))), paths, True
    print(f"reference: classic, {paths} paths per frame (cached for later runs) ...", flush=True)
    run = solve(inputs, config, paths, "classic", seed=12345)
    os.makedirs(cache_dir, exist_ok=True)
    partial = path + ".partial.npz"
    np.savez_compressed(partial, radiosity=run.radiosity, areas=run.areas, stats=json.dumps(run.stats))
    os.replace(partial, path)  # never a half-written cache
    return run, paths, False


def eq4(frames, k, survival, mean_path_length):
    walk = survival * (mean_path_length - 1)
    return (frames * (1 + walk) + k * frames) / (frames + walk + k)


def measure(config, output_dir, cache_dir, pictures):
    inputs = Inputs(config.frames)
    reference, reference_paths, cached = reference_solution(inputs, config, cache_dir)
    middle = int(round(config.frames * 17 / 30)) - 1  # frame 17 of 30, as in the paper's Fig. 2
    results = {"config": config.as_dict(), "reference_paths": reference_paths,
               "reference_cached": cached, "middle_frame": middle,
               "elements": int(reference.radiosity.shape[1]),
               "patches": int(reference.stats["Patches"]), "modes": {}, "curve": {}}
    runs = {}
    for mode in MODES:
        run = solve(inputs, config, config.paths, mode)
        runs[mode] = run
        mse = mse_per_frame(run, reference)
        results["modes"][mode] = {
            "seconds": run.seconds,
            "seconds_shooting": run.stats["SecondsShooting"],
            "seconds_gathering": run.stats["SecondsGathering"],
            "nearest_hit_rays": int(run.stats["ShootingRays"]),
            "shadow_rays": int(run.stats["ShadowRays"]),
            "gathering_rays": int(run.stats["GatheringRays"]),
            "mean_path_length": run.stats["MeanPathLength"],
            "mse_per_frame": mse.tolist(),
            "mse_middle": float(mse[middle]),
            "flicker": flicker(run, reference),
        }
        print(f"{mode:16s} {run.seconds:7.2f} s  MSE(middle) {mse[middle]:.4g}  "
              f"flicker {results['modes'][mode]['flicker']:.4g}", flush=True)

    for mode in MODES:
        points = []
        for paths in config.curve_paths:
            run = runs[mode] if paths == config.paths else solve(inputs, config, paths, mode)
            points.append({"paths": paths, "seconds": run.seconds,
                           "seconds_per_frame": run.seconds / config.frames,
                           "mse_middle": float(mse_per_frame(run, reference)[middle])})
        results["curve"][mode] = points
        print(f"curve {mode}: " + ", ".join(f"{p['paths']}: {p['mse_middle']:.3g}" for p in points),
              flush=True)

    classic, full = results["modes"]["classic"], results["modes"]["full reuse"]
    results["speedup"] = classic["seconds"] / full["seconds"]
    results["speedup_eq4"] = eq4(config.frames, config.gathering_ratio, config.survival,
                                 classic["mean_path_length"])
    results["mse_ratio_middle"] = full["mse_middle"] / classic["mse_middle"]
    results["efficiency_gain"] = (classic["seconds"] * classic["mse_middle"]) / (
        full["seconds"] * full["mse_middle"])
    results["flicker_ratio"] = classic["flicker"] / full["flicker"]
    results["targets"] = {
        "speedup >= 6": results["speedup"] >= 6,
        "MSE(full)/MSE(classic) at middle frame <= 1.5": results["mse_ratio_middle"] <= 1.5,
        "time x MSE gain >= 4": results["efficiency_gain"] >= 4,
        "flicker classic/full >= 3": results["flicker_ratio"] >= 3,
    }
    write_tables(results, output_dir)
    if pictures:
        render_middle_frames(runs, middle, config.frames, output_dir)
    return results


def write_tables(results, output_dir):
    os.makedirs(output_dir, exist_ok=True)
    with open(os.path.join(output_dir, "results.json.partial"), "w") as f:
        json.dump(results, f, indent=1)
    os.replace(os.path.join(output_dir, "results.json.partial"), os.path.join(output_dir, "results.json"))
    with open(os.path.join(output_dir, "modes.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["mode", "seconds", "nearest_hit_rays", "shadow_rays", "gathering_rays",
                    "mse_middle", "flicker"])
        for mode, m in results["modes"].items():
            w.writerow([mode, m["seconds"], m["nearest_hit_rays"], m["shadow_rays"],
                        m["gathering_rays"], m["mse_middle"], m["flicker"]])
    with open(os.path.join(output_dir, "mse_per_frame.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["frame"] + list(results["modes"]))
        frames = len(next(iter(results["modes"].values()))["mse_per_frame"])
        for i in range(frames):
            w.writerow([i + 1] + [m["mse_per_frame"][i] for m in results["modes"].values()])
    with open(os.path.join(output_dir, "time_vs_mse.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["mode", "paths", "seconds", "seconds_per_frame", "mse_middle"])
        for mode, points in results["curve"].items():
            for p in points:
                w.writerow([mode, p["paths"], p["seconds"], p["seconds_per_frame"], p["mse_middle"]])


def render_middle_frames(runs, middle, frames, output_dir):
    """Classic and full reuse side by side, flat-shaded elements so the noise shows."""
    if not os.environ.get("DISPLAY"):
        print("pictures: skipped (no display; run under xvfb-run -a)")
        return
    from vtkmodules.vtkCommonCore import vtkUnsignedCharArray
    from vtkmodules.vtkIOImage import vtkPNGWriter
    from vtkmodules.vtkRenderingCore import (vtkActor, vtkPolyDataMapper, vtkRenderWindow,
                                             vtkRenderer, vtkTextActor, vtkWindowToImageFilter)
    import vtkmodules.vtkRenderingOpenGL2  # noqa: F401
    import vtkmodules.vtkRenderingFreeType  # noqa: F401

    bright = np.percentile(runs["classic"].radiosity[middle] @ [0.2126, 0.7152, 0.0722], 99)
    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(1280, 660)
    for i, mode in enumerate(("classic", "full reuse")):
        radiosity = runs[mode].radiosity[middle]
        mapped = (1 - np.exp(-2.0 / bright * np.clip(radiosity, 0, None))) ** (1 / 2.2)
        colours = vtkUnsignedCharArray()
        colours.SetNumberOfComponents(3)
        for rgb in np.round(255 * mapped).astype(np.uint8):
            colours.InsertNextTuple3(*rgb)
        shown = vtkPolyData()
        shown.CopyStructure(runs[mode].mesh)
        shown.GetCellData().SetScalars(colours)
        mapper = vtkPolyDataMapper()
        mapper.SetInputData(shown)
        mapper.SetScalarModeToUseCellData()
        mapper.SetColorModeToDirectScalars()
        actor = vtkActor()
        actor.SetMapper(mapper)
        actor.GetProperty().LightingOff()
        renderer = vtkRenderer()
        renderer.SetViewport(i * 0.5, 0, (i + 1) * 0.5, 1)
        renderer.AddActor(actor)
        label = vtkTextActor()
        label.SetInput(f"{mode}: {runs[mode].seconds:.1f} s for {frames} frames")
        label.GetTextProperty().SetFontSize(20)
        label.SetPosition(10, 10)
        renderer.AddActor2D(label)
        camera = renderer.GetActiveCamera()
        camera.SetViewAngle(39.3)
        camera.SetFocalPoint(0.278, 0.2744, 0.2796)
        camera.SetPosition(0.278, 0.2744, -0.8)
        camera.SetViewUp(0, 1, 0)
        renderer.ResetCameraClippingRange()
        window.AddRenderer(renderer)
    window.Render()
    grab = vtkWindowToImageFilter()
    grab.SetInput(window)
    writer = vtkPNGWriter()
    writer.SetInputConnection(grab.GetOutputPort())
    writer.SetFileName(os.path.join(output_dir, "middle_frame_classic_vs_full_reuse.png"))
    writer.Write()


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--output", default="output/paper", help="folder for results and pictures")
    parser.add_argument("--cache", default=None, help="folder for the cached reference (default: OUTPUT/cache)")
    parser.add_argument("--quick", action="store_true", help="small configuration for tests")
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--no-pictures", action="store_true")
    args = parser.parse_args(argv)
    config = Config(args.quick)
    config.threads = args.threads
    start = time.time()
    results = measure(config, args.output, args.cache or os.path.join(args.output, "cache"),
                      not args.no_pictures)
    print(f"\nspeed-up of full reuse over classic at N = {config.paths}: {results['speedup']:.2f}x "
          f"(eq. 4 with l = {results['modes']['classic']['mean_path_length']:.2f}: "
          f"{results['speedup_eq4']:.2f}x)")
    print(f"MSE of full reuse / classic at frame {results['middle_frame'] + 1}: {results['mse_ratio_middle']:.2f}; "
          f"time x MSE gain {results['efficiency_gain']:.2f}x; flicker classic / full {results['flicker_ratio']:.2f}x")
    for target, met in results["targets"].items():
        print(f"target {target}: {'met' if met else 'MISSED'}")
    print(f"({time.time() - start:.0f} s; results in {args.output})")
    return results


if __name__ == "__main__":
    main()
    sys.exit(0)
