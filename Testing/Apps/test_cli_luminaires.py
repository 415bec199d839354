"""The command line's luminaires: --point-light, --spot, --light-distribution (IES LM-63),
--luminaire (an area light of the file's opening), a TILT=INCLUDE table against --up, and
--light-lumens, each checked against the closed form of its direct light on a floor, and
their bad values refused with a message naming the option.

A point light of power Phi with the normalised intensity distribution f lights a floor
element at distance r, seen at theta from the floor's normal, with the irradiance
E = Phi f cos(theta) / r^2; the direct radiosity is rho E. Averages over a region of elements
are compared within 4.5 standard deviations of the number of paths that land there.

ctest sets MLR_CLI and MLR_DATA_DIR; by hand:
    MLR_CLI=build/bin/moving-light-radiosity /usr/bin/python3 -m pytest Testing/Apps
"""
import json
import math
import os
import sys

import numpy
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
sys.path.insert(0, os.path.dirname(__file__))
from cli_support import all_files, run  # noqa: E402
from test_cli_rigs_and_sun import (  # noqa: E402
    DISCRETISATION, LAMP, RHO, SIGMAS, disc, read_series, solve, write_floor, write_points)

PATHS = 100000
HEIGHT = 1.0

# Results are stored to within 2^-10 of themselves (16 bits per channel): each of the 16
# error batches, then their mean. A value is within 2 x 2^-10, a ratio of two runs' values
# within 4 x 2^-10, but for powers of two, which scale a stored value exactly.
STORED_RATIO = 4 * 2.0 ** -10


def point_direct(frame, selection, position, density, power=LAMP):
    """rho Phi f(gamma) cos(theta) / r^2 over floor elements, area-weighted, for a light
    whose nadir is -z; `density` maps cos(gamma) to f (1/sr)."""
    d = frame.centre[selection] - numpy.asarray(position, dtype=float)
    r = numpy.linalg.norm(d, axis=1)
    cos = -d[:, 2] / r  # the angle from the nadir is the angle at the floor
    values = RHO * power * density(cos) * cos / r ** 2
    weights = frame.area[selection]
    return (values * weights).sum() / weights.sum()


def assert_point_light(frame, selection, position, density, paths=PATHS):
    expected = point_direct(frame, selection, position, density)
    reach = expected * frame.area[selection].sum() / (RHO * LAMP)
    tolerance = SIGMAS / math.sqrt(paths * reach) + DISCRETISATION
    measured = frame.mean("DirectRadiosity", selection)
    assert measured == pytest.approx([expected] * 3, rel=tolerance), (measured, expected)
    return measured[0]


def point_run(tmp_path, extra, collection, paths=PATHS):
    base = ["--scene", write_floor(tmp_path), "--point-light",
            "--from", f"0,0,{HEIGHT}", "--to", f"0,0,{HEIGHT}", "--frames", "1"]
    return solve(tmp_path, base + extra, collection, paths)


def ring(frame, inner, outer):
    on_floor = numpy.abs(frame.centre[:, 2]) < 1e-9
    r = numpy.hypot(frame.centre[:, 0], frame.centre[:, 1])
    return on_floor & (r > inner) & (r < outer)


def test_point_light_follows_the_inverse_square_law(tmp_path):
    # Lambertian about the nadir: f = cos(gamma) / pi.
    (_, frame), = point_run(tmp_path, [], "lambert/s.pvd")
    assert frame.field("LightPosition") == pytest.approx((0, 0, HEIGHT))
    below = assert_point_light(frame, disc(frame, 0, 0), (0, 0, HEIGHT), lambda c: c / math.pi)
    aside = assert_point_light(frame, ring(frame, 0.9, 1.1), (0, 0, HEIGHT),
                               lambda c: c / math.pi)
    # E = cos^2 / (pi r^2) = cos^4 / (pi h^2): at 1 beside a light 1 up, cos^4(45 degrees) =
    # 0.25; over the ring and the disc, area-weighted, the closed form gives 0.273.
    ratio = (point_direct(frame, ring(frame, 0.9, 1.1), (0, 0, HEIGHT), lambda c: c / math.pi) /
             point_direct(frame, disc(frame, 0, 0), (0, 0, HEIGHT), lambda c: c / math.pi))
    assert ratio == pytest.approx(0.25, rel=0.1)
    assert aside / below == pytest.approx(ratio, rel=0.1)


def test_spot_lights_its_cone_only(tmp_path):
    half = 20.0
    (_, frame), = point_run(tmp_path, ["--spot", str(half)], "spot/s.pvd")
    inside = 1 / (2 * math.pi * (1 - math.cos(math.radians(half))))
    assert_point_light(frame, disc(frame, 0, 0, 0.25), (0, 0, HEIGHT),
                       lambda c: numpy.full_like(c, inside))
    # The cone meets the floor at tan(20 degrees) = 0.36: nothing lands beyond it.
    beyond = ring(frame, 0.45, 2.0)
    assert beyond.any()
    assert numpy.all(frame.cells("DirectRadiosity")[beyond] == 0)


def write_uniform_hemisphere(path):
    """An IES LM-63-2002 file of 1000 cd over the lower hemisphere, none above."""
    path.write_text("IESNA:LM-63-2002\n[TEST] uniform downlight\nTILT=NONE\n"
                    "1 -1 1 3 1 1 2 0 0 0\n1 1 0\n0 45 90\n0\n1000 1000 1000\n")
    return os.path.basename(str(path))


def test_light_distribution_file_shapes_the_light(tmp_path):
    ies = write_uniform_hemisphere(tmp_path / "down.ies")
    (_, frame), = point_run(tmp_path, ["--light-distribution", ies, "--light-power", "100"],
                            "ies/s.pvd")
    # Uniform intensity over the lower hemisphere: f = 1 / (2 pi), so that E falls as
    # cos / r^2, not cos^2 / r^2 as for a Lambertian light.
    uniform = lambda c: numpy.full_like(c, 1 / (2 * math.pi))  # noqa: E731
    below = assert_point_light(frame, disc(frame, 0, 0), (0, 0, HEIGHT), uniform)
    aside = assert_point_light(frame, ring(frame, 0.9, 1.1), (0, 0, HEIGHT), uniform)
    assert aside / below == pytest.approx(math.cos(math.pi / 4) ** 3, rel=0.1)


def test_light_distribution_file_gives_its_own_flux(tmp_path):
    # Without --light-lumens or --light-power the light emits the file's flux: 1000 cd over
    # the lower hemisphere (absolute photometry) is 2000 pi lm, at 179 lm/W of white light.
    ies = write_uniform_hemisphere(tmp_path / "own.ies")
    own = point_run(tmp_path, ["--light-distribution", ies], "own/s.pvd")[0][1]
    watts = point_run(tmp_path, ["--light-distribution", ies, "--light-power", "100"],
                      "own_watts/s.pvd")[0][1]
    lumens = point_run(tmp_path, ["--light-distribution", ies, "--light-lumens", "8950"],
                       "own_lumens/s.pvd")[0][1]
    direct = watts.cells("DirectRadiosity")
    lit = direct > 0
    assert lit.any()
    # The same paths (same seed): the radiosities scale with the power alone.
    assert own.cells("DirectRadiosity")[lit] / direct[lit] == pytest.approx(
        2000 * math.pi / 179 / 100, rel=STORED_RATIO)
    # --light-lumens wins over the file's flux: 8950 lm is 50 W.
    assert lumens.cells("DirectRadiosity")[lit] / direct[lit] == pytest.approx(0.5, rel=1e-6)


def test_stats_record_the_point_light_as_solved(tmp_path):
    """--stats said "built-in Cornell box" and LightPower's 100 W for an IES point light: it
    records the light's kind, file, flux and the power solved."""
    ies = write_uniform_hemisphere(tmp_path / "own.ies")
    result = run(["--scene", write_floor(tmp_path), "--point-light", "--from", f"0,0,{HEIGHT}",
                  "--to", f"0,0,{HEIGHT}", "--frames", "1", "--light-distribution", ies,
                  "--paths", "2000", "--output", "out/s.pvd", "--stats", "out/s.json"], tmp_path)
    assert result.returncode == 0, result.stderr
    stats = json.loads((tmp_path / "out" / "s.json").read_text())
    assert stats["light"] == "point light"
    lighting = stats["lighting"]
    assert lighting["kind"] == "point light" and lighting["distributionFile"] == ies
    assert lighting["powerFrom"] == "the distribution file's flux"
    assert lighting["lumens"] == pytest.approx(2000 * math.pi, rel=1e-9)
    assert lighting["luminousEfficacy"] == 179
    assert lighting["powerW"] == pytest.approx([2000 * math.pi / 179] * 3, rel=1e-9)
    assert stats["settings"]["lightPower"] == lighting["powerW"]
    assert stats["frames"][0]["lightPosition"] == [0, 0, HEIGHT]

    # --light-lumens with a colour: the colour scaled to those lumens.
    result = run(["--scene", write_floor(tmp_path), "--point-light", "--from", f"0,0,{HEIGHT}",
                  "--to", f"0,0,{HEIGHT}", "--frames", "1", "--spot", "40",
                  "--light-lumens", "8950", "--light-power", "2,1,0", "--paths", "2000",
                  "--output", "out/c.pvd", "--stats", "out/c.json"], tmp_path)
    assert result.returncode == 0, result.stderr
    lighting = json.loads((tmp_path / "out" / "c.json").read_text())["lighting"]
    scale = 50 / (0.2126 * 2 + 0.7152 * 1)
    assert lighting["powerW"] == pytest.approx([2 * scale, scale, 0], rel=1e-9)
    assert lighting["lumens"] == pytest.approx(8950, rel=1e-12)
    assert lighting["powerFrom"] == "--light-lumens"
    assert lighting["spot"] == {"halfAngleDegrees": 40, "softEdgeDegrees": 0}

    # A luminaire of an opening: its power is the Light output's, the file's flux.
    (tmp_path / "opening.ies").write_text(
        "IESNA:LM-63-2002\n[TEST] uniform downlight\nTILT=NONE\n1 -1 1 3 1 1 2 0.2 0.2 0\n"
        "1 1 0\n0 45 90\n0\n1000 1000 1000\n")
    result = run(["--scene", write_floor(tmp_path), "--luminaire", "--light-distribution",
                  "opening.ies", "--from", f"0,0,{HEIGHT}", "--to", f"0,0,{HEIGHT}", "--frames",
                  "1", "--paths", "2000", "--output", "out/l.pvd", "--stats", "out/l.json"],
                 tmp_path)
    assert result.returncode == 0, result.stderr
    stats = json.loads((tmp_path / "out" / "l.json").read_text())
    lighting = stats["lighting"]
    assert stats["light"] == "luminaire" and lighting["emitsFrom"] == "the file's luminous opening"
    assert lighting["powerW"] == pytest.approx([2000 * math.pi / 179] * 3, rel=1e-6)
    assert lighting["powerFrame"] == 0


def test_stats_take_the_point_light_from_the_filter(tmp_path):
    """--stats took a point light's power from LightPower scaled to --light-lumens, itself:
    without the TILT factor the filter solved with. It takes the Light output's: a TILT table of
    1 at 0 and 0.4 at 90 degrees, with up +y, tilts the light (nadir -z) by 90 degrees, and
    the filter emits 0.4 of the 8950 lm asked for, in the colour (2, 1, 0)."""
    (tmp_path / "tilted.ies").write_text(
        "IESNA:LM-63-2002\n[TEST] tilt\nTILT=INCLUDE\n1\n2\n0 90\n1 0.4\n"
        "1 -1 1 3 1 1 2 0 0 0\n1 1 0\n0 45 90\n0\n1000 1000 1000\n")
    result = run(["--scene", write_floor(tmp_path), "--point-light", "--from", f"0,0,{HEIGHT}",
                  "--to", f"0.5,0,{HEIGHT}", "--frames", "2", "--light-distribution",
                  "tilted.ies", "--light-lumens", "8950", "--light-power", "2,1,0", "--up",
                  "0,1,0", "--paths", "2000", "--output", "out/t.pvd", "--stats", "out/t.json"],
                 tmp_path)
    assert result.returncode == 0, result.stderr
    stats = json.loads((tmp_path / "out" / "t.json").read_text())
    lighting = stats["lighting"]
    scale = 0.4 * 50 / (0.2126 * 2 + 0.7152 * 1)
    assert lighting["powerW"] == pytest.approx([2 * scale, scale, 0], rel=1e-12, abs=1e-12)
    assert lighting["lumens"] == pytest.approx(0.4 * 8950, rel=1e-12)
    # The light is tilted alike in both frames: the first of the brightest.
    assert lighting["powerFrame"] == 0 and lighting["powerFrom"] == "--light-lumens"
    assert stats["settings"]["lightPower"] == lighting["powerW"]
    assert [f["lightPosition"] for f in stats["frames"]] == [[0, 0, HEIGHT], [0.5, 0, HEIGHT]]
    assert [f["powerW"] for f in stats["frames"]] == [lighting["powerW"]] * 2


def test_stats_give_each_frames_power_and_the_brightest(tmp_path):
    """--stats posed the light in one frame (the first, or the last when streamed), so a light
    off there reported 0 W and 0 lm. Each frame now has its own power, the trajectory's Power
    factor applied, as the frames' field data LightPower and LightLuminousFlux give it, and the
    light's powerW is its brightest frame's."""
    trajectory = write_points(tmp_path / "dims.vtp", [(0, 0, HEIGHT), (0.2, 0, HEIGHT),
                                                      (0.4, 0, HEIGHT)], Power=[0.0, 1.0, 0.25])
    for streamed in ([], ["--frames-per-chunk", "2", "--chunk-overlap", "0"]):
        out = "chunked" if streamed else "whole"
        result = run(["--scene", write_floor(tmp_path), "--point-light", "--trajectory",
                      trajectory, "--light-lumens", "1790", "--paths", "2000", "--output",
                      f"{out}/s.pvd", "--stats", f"{out}/s.json"] + streamed, tmp_path)
        assert result.returncode == 0, result.stderr
        stats = json.loads((tmp_path / out / "s.json").read_text())
        watts = 1790 / 179  # of luminance, white: 10 W per channel
        numpy.testing.assert_allclose([f["powerW"] for f in stats["frames"]],
                                      [[0] * 3, [watts] * 3, [watts / 4] * 3], rtol=1e-12,
                                      err_msg=out)
        assert [f["lumens"] for f in stats["frames"]] == pytest.approx(
            [0, 1790, 1790 / 4], rel=1e-12), out
        lighting = stats["lighting"]
        assert lighting["powerFrame"] == 1, out
        assert lighting["powerW"] == pytest.approx([watts] * 3, rel=1e-12), out
        assert lighting["lumens"] == pytest.approx(1790, rel=1e-12), out
        # The series' own field data says the same.
        last = read_series(tmp_path, f"{out}/s.pvd")[2][1]
        assert last.field("LightPower") == pytest.approx([watts / 4] * 3, rel=1e-12), out
        assert last.field("LightLuminousFlux") == pytest.approx(1790 / 4, rel=1e-12), out


def test_light_lumens_set_the_power_through_the_efficacy(tmp_path):
    watts = point_run(tmp_path, [], "watts/s.pvd")[0][1]
    # 8950 lm at 179 lm/W is 50 W of luminance: half the default 100 W white light, the same
    # paths (same seed), so half the radiosity to rounding.
    lumens = point_run(tmp_path, ["--light-lumens", "8950"], "lumens/s.pvd")[0][1]
    direct = watts.cells("DirectRadiosity")
    lit = direct > 0
    assert lit.any()
    assert lumens.cells("DirectRadiosity")[lit] / direct[lit] == pytest.approx(0.5, rel=1e-6)
    # A coloured light keeps its colour: (2, 1, 0) scaled so that its luminance is 50 W.
    coloured = point_run(tmp_path, ["--light-lumens", "8950", "--light-power", "2,1,0"],
                         "coloured/s.pvd")[0][1].cells("DirectRadiosity")
    scale = 50 / (0.2126 * 2 + 0.7152 * 1)
    assert coloured[lit[:, 0], 0] / direct[lit[:, 0], 0] == pytest.approx(
        2 * scale / 100, rel=STORED_RATIO)
    assert coloured[lit[:, 1], 1] / direct[lit[:, 1], 1] == pytest.approx(
        scale / 100, rel=STORED_RATIO)
    assert numpy.all(coloured[:, 2] == 0)


def test_luminaire_emits_from_its_opening_like_the_point_light_far_off(tmp_path):
    # A 0.2 m square opening 1 m up: beyond a few opening sizes it lights the floor as the
    # point light of its distribution does (the near field's correction, of order
    # (0.1 / 1)^2, is within DISCRETISATION).
    ies = "opening.ies"
    (tmp_path / ies).write_text("IESNA:LM-63-2002\n[TEST] uniform downlight\nTILT=NONE\n"
                                "1 -1 1 3 1 1 2 0.2 0.2 0\n1 1 0\n0 45 90\n0\n"
                                "1000 1000 1000\n")
    base = ["--scene", write_floor(tmp_path), "--luminaire", "--light-distribution", ies,
            "--light-power", "100", "--from", f"0,0,{HEIGHT}", "--to", f"0,0,{HEIGHT}",
            "--frames", "1"]
    (_, frame), = solve(tmp_path, base, "luminaire/s.pvd", PATHS)
    uniform = lambda c: numpy.full_like(c, 1 / (2 * math.pi))  # noqa: E731
    assert_point_light(frame, disc(frame, 0, 0), (0, 0, HEIGHT), uniform)
    assert_point_light(frame, ring(frame, 0.9, 1.1), (0, 0, HEIGHT), uniform)


def test_tilt_table_scales_the_light_by_the_tilt_from_up(tmp_path):
    # A luminaire aimed along -z is untilted with the default up (+z) and tilted 90 degrees
    # with --up 0,1,0: a TILT table of 1 at 0 and 0.4 at 90 degrees gives it 1 and 0.4 of the
    # TILT=NONE light, along the same paths.
    def write(name, tilt):
        (tmp_path / name).write_text("IESNA:LM-63-2002\n[TEST] tilt\n" + tilt + "\n"
                                     "1 -1 1 3 1 1 2 0 0 0\n1 1 0\n0 45 90\n0\n"
                                     "1000 1000 1000\n")
        return name
    plain = write("plain.ies", "TILT=NONE")
    tilted = write("tilted.ies", "TILT=INCLUDE\n1\n2\n0 90\n1 0.4")
    runs = {}
    for key, ies, extra in (("plain", plain, []), ("down", tilted, []),
                            ("sideways", tilted, ["--up", "0,1,0"])):
        runs[key] = point_run(tmp_path, ["--light-distribution", ies, "--light-power", "100"] +
                              extra, f"{key}/s.pvd", 20000)[0][1].cells("DirectRadiosity")
    lit = runs["plain"] > 0
    assert lit.any()
    assert runs["down"][lit] / runs["plain"][lit] == pytest.approx(1.0, rel=1e-6)
    assert runs["sideways"][lit] / runs["plain"][lit] == pytest.approx(0.4, rel=STORED_RATIO)


@pytest.mark.parametrize("args, words", [
    (["--luminaire"], "--luminaire"),
    (["--luminaire=yes"], "--luminaire"),
    (["--luminaire", "--point-light", "--light-distribution", "a.ies"], "--luminaire"),
    (["--up", "0,1,0"], "--up"),
    (["--spot", "0"], "--spot"),
    (["--spot", "200"], "--spot"),
    (["--spot", "30,-1"], "--spot"),
    (["--spot", "30,5,1"], "--spot"),
    (["--light-lumens", "-5"], "--light-lumens"),
    (["--light-lumens", "0"], "--light-lumens"),
    (["--light-lumens", "1e45"], "--light-lumens is 1e+45: give the luminaire's luminous flux in "
                                 "lumens, above 0 and at most 1e+30"),
    (["--light-distribution", "lamp.txt"], "--light-distribution"),
    (["--light-distribution", "a.ies", "--spot", "30"], "--light-distribution"),
    (["--point-light=yes"], "--point-light"),
    (["--point-light", "--light", "lamp.vtp"], "--point-light"),
])
def test_bad_luminaire_options_are_refused_naming_them(tmp_path, args, words):
    floor = write_floor(tmp_path)
    result = run(["--scene", floor, "--from", "0,0,1", "--to", "0,0,1", "--frames", "1",
                  "--output", "out/s.pvd"] + args, tmp_path)
    assert result.returncode == 2, result.stderr
    assert words in result.stderr, result.stderr
    assert all_files(tmp_path) == [floor]


def test_missing_or_bad_photometric_file_names_it(tmp_path):
    floor = write_floor(tmp_path)
    (tmp_path / "broken.ies").write_text("IESNA:LM-63-2002\nTILT=NONE\n1 -1 1\n")
    # Finite candela of an infinite irradiance in single precision: 1e300 cd over a hemisphere.
    (tmp_path / "huge.ies").write_text("IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 3 1 1 2 0 0 0\n"
                                       "1 1 0\n0 45 90\n0\n1e300 1e300 1e300\n")
    for name in ("missing.ies", "broken.ies", "huge.ies"):
        result = run(["--scene", floor, "--point-light", "--from", "0,0,1", "--to", "0,0,1",
                      "--frames", "1", "--light-distribution", name, "--output", "out/s.pvd"],
                     tmp_path)
        assert result.returncode == 1, result.stderr
        assert name in result.stderr, result.stderr
        assert not (tmp_path / "out").exists()
