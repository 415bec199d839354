"""The command line's sky: --sky, --sky-diffuse-horizontal, --up, the sky following a sun
path with --sun-irradiance 0, its Perez luminous efficacy, and its bad inputs.

An open ground square is the scene: nothing hides any of its sky, so its direct radiosity is
rho E_dh under every model and in every frame. A path reaches it with probability
q = A / (pi R^2) for the uniform sky (R: the bounding sphere's radius; Lambda = E_dh), each
scoring the same: the tolerance is SIGMAS binomial standard deviations. A sky that changes
over frames reuses the paths of all of them, whose weights spread: twice that.

ctest sets MLR_CLI and MLR_DATA_DIR; by hand:
    MLR_CLI=build/bin/moving-light-radiosity /usr/bin/python3 -m pytest Testing/Apps
"""
import math

import pytest

from test_cli_rigs_and_sun import PARIS, PATHS, RHO, SIGMAS, Polygons, run, solve

HALF = 2.0
EDH = 200.0


def write_ground(directory):
    return Polygons().add([(-HALF, -HALF, 0), (HALF, -HALF, 0), (HALF, HALF, 0),
                           (-HALF, HALF, 0)]).write(directory / "ground.vtp")


def relative_sigma():
    area = (2 * HALF) ** 2
    radius = 0.5 * math.sqrt(2) * 2 * HALF
    q = area / (math.pi * radius ** 2)
    return math.sqrt((1 - q) / (PATHS * q))


@pytest.mark.parametrize("model", ["uniform", "cie-overcast"])
def test_open_ground_gets_rho_times_the_diffuse_horizontal(tmp_path, model):
    frames = solve(tmp_path, ["--scene", write_ground(tmp_path), "--sky", model,
                              "--sky-diffuse-horizontal", str(EDH)])
    assert len(frames) == 1
    frame = frames[0][1]
    everything = frame.area > 0
    expected = RHO * EDH
    for channel in frame.mean("DirectRadiosity", everything):
        # The overcast sky draws its directions from its own radiance: a path still scores
        # the same, but q is smaller by Lambda / E_dh = 9/7; its tolerance covers that.
        assert channel == pytest.approx(expected, rel=SIGMAS * relative_sigma() * 1.2)
    # Illuminance from the Perez diffuse efficacy, stated in the field data.
    efficacy = frame.field("LuminousEfficacy")
    assert 90 < efficacy < 160
    model_note = frame.grid.GetFieldData().GetAbstractArray("LuminousEfficacyModel")
    assert model_note is not None and "Perez" in model_note.GetValue(0)
    irradiance = frame.cells("Irradiance")
    lux = frame.cells("Illuminance")[:, 0]
    luminance = irradiance @ [0.2126, 0.7152, 0.0722]
    assert lux == pytest.approx(efficacy * luminance, rel=1e-5, abs=1e-3)


def test_clear_sky_follows_the_sun_path_without_direct_sun(tmp_path):
    frames = solve(tmp_path, ["--scene", write_ground(tmp_path), "--sun-path",
                              PARIS + ",08:00,16:00,240", "--time-zone", "2",
                              "--sun-irradiance", "0", "--sky", "cie-clear",
                              "--sky-diffuse-horizontal", str(EDH)])
    # The frames of the sun path are kept, though the sun gives nothing directly.
    assert [t for t, _ in frames] == [8.0, 12.0, 16.0]
    for _, frame in frames:
        assert frame.field("SunElevation") > 0
        for channel in frame.mean("DirectRadiosity", frame.area > 0):
            assert channel == pytest.approx(RHO * EDH, rel=2 * SIGMAS * relative_sigma() * 1.5)


@pytest.mark.parametrize("model", ["uniform", "cie-clear", "perez"])
def test_the_sky_is_dark_at_night(tmp_path, model):
    """--sky-diffuse-horizontal is a daylight sky's. It lit the ground at midnight, with the sun
    13 to 18 degrees below the horizon (QA: about 10,000 lx), and counted night as daylight in
    the sensors' metrics. A frame whose sun is below the horizon is now night, sky included."""
    frames = solve(tmp_path, ["--scene", write_ground(tmp_path), "--sun-path",
                              PARIS + ",00:00,12:00,360", "--time-zone", "2", "--sky", model,
                              "--sky-diffuse-horizontal", str(EDH)])
    (_, night), _, (_, noon) = frames
    assert night.field("SunElevation") < -10 and noon.field("SunElevation") > 50
    for name in ("Radiosity", "Irradiance", "Illuminance"):
        assert not night.cells(name).any(), name
    # By day the sky still gives E_dh, the sun the rest.
    assert min(noon.mean("Irradiance", noon.area > 0)) > EDH


def test_up_turns_the_sky(tmp_path):
    # With the zenith along -z the ground's underside faces the sky and gets E_dh (100 by
    # default): the Irradiance of a two-sided surface counts both sides.
    frames = solve(tmp_path, ["--scene", write_ground(tmp_path), "--sky", "uniform",
                              "--up", "0,0,-1"])
    frame = frames[0][1]
    assert frame.mean("Irradiance", frame.area > 0)[0] == pytest.approx(100.0, rel=SIGMAS * relative_sigma())


@pytest.mark.parametrize("args, words", [
    (["--sky", "clear"], "give uniform, cie-overcast, cie-clear or perez"),
    (["--sky", "cie-clear"], "follows the sun"),
    (["--sky", "perez"], "follows the sun"),
    (["--sky-diffuse-horizontal", "10"], "--sky-diffuse-horizontal needs --sky"),
    (["--sky", "uniform", "--sky-diffuse-horizontal", "-1"], "0 or above"),
    (["--up", "0,0,1"], "--up needs --sun-path"),
    # Given and ignored before: the sky's Perez efficacy, no light to take them, the lights
    # left out of a solve with a sky.
    (["--sky", "uniform", "--luminous-efficacy", "90"],
     "--luminous-efficacy with --sky: daylight's Illuminance takes each frame's Perez"),
    (["--sun-path", "48.85,2.35,2026-06-21,08:00,18:00,60", "--luminous-efficacy", "90"],
     "--luminous-efficacy with the sun: daylight's Illuminance takes each frame's Perez"),
    (["--sky", "uniform", "--light-lumens", "1000"], "--light-lumens is for a light, and the "
                                                      "scene has none"),
    (["--sky", "uniform", "--spot", "30"], "--spot is for a light, and the scene has none"),
    (["--sky", "uniform", "--light-distribution", "a.ies"],
     "--light-distribution is for a light, and the scene has none"),
    (["--sky", "uniform", "--point-light", "--from", "0,0,1", "--to", "1,0,1"],
     "--point-light with --sky: a sky lights the scene beside the sun or alone"),
    (["--sky", "uniform", "--light-material", "m", "--from", "0,0,1", "--to", "1,0,1"],
     "--light-material with --sky"),
    (["--sky", "uniform", "--light", "lamp.vtp", "--from", "0,0,1", "--to", "1,0,1"],
     "--light with --sky"),
])
def test_bad_sky_options_are_refused_by_name(tmp_path, args, words):
    result = run(["--scene", write_ground(tmp_path)] + args + ["--output", "o/s.pvd"], tmp_path)
    assert result.returncode != 0
    assert words in result.stderr
    assert not (tmp_path / "o").exists()


def test_weather_refuses_a_luminous_efficacy_it_would_ignore(tmp_path):
    result = run(["--scene", write_ground(tmp_path), "--weather", "w.epw",
                  "--luminous-efficacy", "90", "--output", "o/s.pvd"], tmp_path)
    assert result.returncode == 2
    assert "--luminous-efficacy with --weather: daylight's Illuminance" in result.stderr
    assert not (tmp_path / "o").exists()


def test_the_sky_needs_a_scene(tmp_path):
    result = run(["--sky", "uniform"], tmp_path)
    assert result.returncode != 0
    assert "the sky needs --scene" in result.stderr
