"""mlr-benchmark --case annual at a small size (one day of the shipped weather file, few paths,
3 classic frames): it runs, and its figures are finite and consistent with what it was asked.
Figures at full size are in Documentation/Performance.md; none is asserted here.
"""
import json
import math
import os
import subprocess

import pytest


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("annual")
    result = subprocess.run(
        [os.environ["MLR_BENCHMARK"], "--case", "annual", "--paths", "3000", "--dates",
         "06-21,06-21", "--classic-frames", "3", "--reference-factor", "2", "--cache", "",
         "--json", str(folder / "annual.json")],
        capture_output=True, text=True, timeout=240)
    assert result.returncode == 0, result.stderr
    with open(folder / "annual.json") as f:
        return result.stdout, json.load(f)["annual"]


def test_the_figures_are_finite_and_consistent(run):
    out, figures = run
    assert "=== A year of daylight on the town block ===" in out
    assert "Radiance 5-phase" in out
    for key, value in figures.items():
        assert math.isfinite(value), key
    assert figures["classic_frames"] == 3
    assert 10 <= figures["frames"] <= 24  # the daylit hours of June 21
    assert 900 <= figures["sensors"] <= 1100
    # One sun shadow ray per sensor and daylit frame at most; 512 hemisphere rays each.
    assert 0 < figures["sensor_shadow_rays"] <= figures["sensors"] * figures["frames"]
    assert figures["sensor_gathering_rays"] == 512 * figures["sensors"]
    assert figures["mse_ratio_worst"] >= figures["mse_ratio_mean"] > 0


@pytest.mark.parametrize("extra,words", [
    (["--dates", "June"], "MM-DD,MM-DD"),
    (["--classic-frames", "0"], "--classic-frames"),
    (["--weather", "/nonexistent.epw"], "nonexistent"),
])
def test_bad_options_are_named(extra, words):
    result = subprocess.run([os.environ["MLR_BENCHMARK"], "--case", "annual", "--cache", ""] + extra,
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 1, result.stdout
    assert words in result.stderr, result.stderr
