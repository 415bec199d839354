"""mlr-benchmark --case spotlight at a small size (few paths, 4 frames): it runs, and prints
its table, ratios and shadow-ray rates as finite numbers. Figures at full size are in
Documentation/Performance.md; none is asserted here.
"""
import json
import math
import os
import re
import subprocess

import pytest

NUMBER = r"([-+0-9.eE]+|nan|-?inf)"


def finite(text):
    value = float(text)
    assert math.isfinite(value), text
    return value


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("spotlight")
    result = subprocess.run(
        [os.environ["MLR_BENCHMARK"], "--case", "spotlight", "--paths", "3000", "--frames", "4",
         "--reference-factor", "2", "--cache", "", "--json", str(folder / "spot.json")],
        capture_output=True, text=True, timeout=240)
    assert result.returncode == 0, result.stderr
    with open(folder / "spot.json") as f:
        return result.stdout, json.load(f)


def test_table_has_both_modes_and_three_frames(run):
    out, _ = run
    assert "=== Panning IES spot ===" in out
    header = next(line for line in out.splitlines() if line.startswith("mode "))
    assert re.findall(r"MSE (frame \d+)", header) == ["frame 1", "frame 2", "frame 4"]
    for mode in ("classic", "full reuse"):
        row = next(line for line in out.splitlines() if line.startswith(mode + " "))
        values = row[len(mode):].split()
        # total s, s/frame, shoot s, gather s, CPU s, 3 ray counts, 3 MSEs and their mean
        assert len(values) == 12, row
        for value in values:
            finite(value)
        assert all(float(v) > 0 for v in values[-4:]), row


def test_ratios_and_rates_are_printed(run):
    out, _ = run
    speedup = re.search(r"Panning IES spot: full reuse is " + NUMBER + r"x faster", out)
    assert speedup and finite(speedup.group(1)) > 0
    ratios = re.search(r"MSE of full reuse / classic: frame 1 " + NUMBER + "; frame 2 " + NUMBER +
                       "; frame 4 " + NUMBER + "; mean over frames " + NUMBER + r"\.", out)
    assert ratios, out
    for i in range(1, 5):
        assert finite(ratios.group(i)) > 0
    ms = re.search(r"ms per frame: classic " + NUMBER + ", full reuse " + NUMBER, out)
    assert ms and finite(ms.group(1)) > 0 and finite(ms.group(2)) > 0
    rates = re.search(r"Their rate in the solver: " + NUMBER + r" M/s .*bare Embree's "
                      r"rtcOccluded16 on the same scene: " + NUMBER + " M/s", out)
    assert rates, out
    finite(rates.group(1))
    assert finite(rates.group(2)) > 0


def test_json_matches_the_case(run):
    _, results = run
    spot = results["panning_spot"]
    assert spot["frames"] == 4 and spot["paths_per_frame"] == 3000
    assert spot["reference_paths_per_frame"] == 6000
    assert [f["frame"] for f in spot["frames_reported"]] == [1, 2, 4]
    classic, full = spot["modes"]
    # Classic casts no shadow rays; full reuse asks for the visibility of the other frames.
    assert classic["shadow_rays"] == 0 and full["shadow_rays"] > 0
    assert math.isfinite(spot["solver_shadow_rays_per_second"])
    assert spot["bare_shadow_rays_per_second"] > 0


def test_one_frame_is_refused():
    result = subprocess.run(
        [os.environ["MLR_BENCHMARK"], "--case", "spotlight", "--frames", "1", "--cache", ""],
        capture_output=True, text=True, timeout=60)
    assert result.returncode == 1
    assert "the panning spot needs at least 2 frames (--frames)" in result.stderr


def test_gathering_ratio_reaches_every_solve(run, tmp_path):
    _, results = run
    default = results["panning_spot"]
    result = subprocess.run(
        [os.environ["MLR_BENCHMARK"], "--case", "spotlight", "--paths", "3000", "--frames", "4",
         "--reference-factor", "2", "--cache", "", "--gathering-ratio", "64",
         "--json", str(tmp_path / "spot.json")],
        capture_output=True, text=True, timeout=240)
    assert result.returncode == 0, result.stderr
    with open(tmp_path / "spot.json") as f:
        spot = json.load(f)["panning_spot"]
    assert default["k"] == 1 and spot["k"] == 64
    # k N gathering rays per frame over the gathering sides, at least one each: at N = 3,000
    # and k = 1 every side casts one, so full reuse's one set counts them. At k = 64 a side
    # casts the whole part of 64 N / sides or one more (probability: the fraction), so the
    # sides cast 64 N give or take sqrt(sides / 4); classic casts the same set every frame.
    sides = default["modes"][1]["gathering_rays"]
    assert 3000 < sides and default["modes"][0]["gathering_rays"] == 4 * sides
    classic, full = spot["modes"]
    assert abs(full["gathering_rays"] - 64 * 3000) <= 5 * math.sqrt(sides / 4)
    assert classic["gathering_rays"] == 4 * full["gathering_rays"]


@pytest.mark.parametrize("ratio", ["0", "-1", "65", "nan", "4x", ""])
def test_gathering_ratio_out_of_range_is_refused(ratio):
    result = subprocess.run(
        [os.environ["MLR_BENCHMARK"], "--case", "spotlight", "--frames", "4", "--cache", "",
         "--gathering-ratio", ratio],
        capture_output=True, text=True, timeout=60)
    assert result.returncode == 2
    assert "--gathering-ratio must be above 0 and at most 64" in result.stderr


@pytest.mark.parametrize("case", ["paper", "ends", "long"])
def test_gathering_ratio_is_refused_where_it_is_ignored(case):
    result = subprocess.run(
        [os.environ["MLR_BENCHMARK"], "--gathering-ratio", "2", "--case", case, "--cache", ""],
        capture_output=True, text=True, timeout=60)
    assert result.returncode == 2
    assert f"--case {case} keeps k = 1" in result.stderr
