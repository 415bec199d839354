"""Benchmarks/mesh_bias.py at a small size (20,000 paths, 2 seeds): it runs, finds every face
of both scenes on both meshes, the fine mesh has about 16 times the patches, and the
figures are finite. Figures at full size are in Documentation/Performance.md; none is
asserted here (at this size the noise is far above the bias).
"""
import json
import math
import os
import subprocess
import sys

import pytest

SCRIPT = os.path.join(os.environ["MLR_SOURCE_DIR"], "Benchmarks", "mesh_bias.py")


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("mesh-bias")
    result = subprocess.run(
        [sys.executable, SCRIPT, "--cli", os.environ["MLR_CLI"], "--paths", "20000",
         "--seeds", "2", "--threads", "2", "--output", str(folder)],
        capture_output=True, text=True, timeout=280)
    assert result.returncode == 0, result.stderr
    with open(folder / "results.json") as f:
        return result.stdout, json.load(f)


def test_both_scenes_every_face_on_both_meshes(run):
    out, results = run
    assert set(results) == {"CornellBox-Original", "paper room"}
    # Floor, ceiling, three walls, two boxes' five visible faces each (the light is black).
    for name, faces in (("CornellBox-Original", 15), ("paper room", 15)):
        r = results[name]
        assert len(r["faces"]) == faces, (name, [f["normal"] for f in r["faces"]])
        assert 12 < r["finePatches"] / r["patches"] < 20, r
        assert r["patchEdge"] > 0
        for face in r["faces"]:
            for key in ("default", "fine", "difference", "stdError", "area"):
                assert math.isfinite(face[key]), (name, face)
            assert face["default"] > 0 and face["fine"] > 0
    assert out.count("worst face:") == 2


def test_one_seed_is_refused():
    result = subprocess.run([sys.executable, SCRIPT, "--seeds", "1"], capture_output=True,
                            text=True, timeout=60)
    assert result.returncode == 2
    assert "--seeds must be at least 2" in result.stderr
