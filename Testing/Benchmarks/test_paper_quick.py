"""The paper benchmark at a small size (few patches, 6 frames, few paths): the qualitative
claims that hold at any size. Figures at the paper's size are in the README, from
Tools/run-paper-benchmark.sh; they are never asserted here.
"""
import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, os.pardir, "Benchmarks"))
import paper_benchmark  # noqa: E402


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    folder = tmp_path_factory.mktemp("paper")
    return paper_benchmark.measure(paper_benchmark.Config(quick=True), str(folder),
                                   str(folder / "cache"), pictures=False)


def rays(mode):
    return mode["nearest_hit_rays"] + mode["shadow_rays"] + mode["gathering_rays"]


def test_reuse_casts_fewer_rays_than_classic(results):
    modes = results["modes"]
    classic = modes["classic"]
    for name in ("gathering reuse", "shooting reuse", "full reuse"):
        assert rays(modes[name]) < rays(classic), name
    # Reusing gathering divides its rays by the frame count; reusing shooting divides the
    # nearest-hit rays of the walks.
    frames = results["config"]["frames"]
    assert modes["gathering reuse"]["gathering_rays"] * frames == pytest.approx(classic["gathering_rays"], rel=0.01)
    assert modes["full reuse"]["nearest_hit_rays"] * 3 < classic["nearest_hit_rays"]
    assert classic["shadow_rays"] == 0 and modes["full reuse"]["shadow_rays"] > 0


def test_error_of_every_mode_falls_when_paths_grow(results):
    for mode, points in results["curve"].items():
        errors = [p["mse_middle"] for p in points]
        # 4x the paths: the MSE falls about 4x; at least 2x leaves room for noise.
        assert errors[1] < errors[0] / 2, mode


def test_full_reuse_flickers_less_than_classic(results):
    assert results["modes"]["full reuse"]["flicker"] < results["modes"]["classic"]["flicker"]
    # Reused gathering alone correlates the frames too.
    assert results["modes"]["gathering reuse"]["flicker"] < results["modes"]["classic"]["flicker"]


def test_tables_are_written(results, tmp_path_factory):
    # measure() wrote them next to results.json; the CSVs carry one row per mode and frame.
    assert results["elements"] > 0 and results["patches"] * 4 == results["elements"]
    assert len(results["modes"]["classic"]["mse_per_frame"]) == results["config"]["frames"]
