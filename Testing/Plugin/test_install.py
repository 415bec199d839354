"""`cmake --install` puts the plugin in ParaView's plugin layout, <prefix>/<libdir>/
paraview-5.11/plugins/MovingLightRadiosity/MovingLightRadiosity.so, where it finds its
library through its RPATH (not in the build tree), and Debian's pvbatch, pvpython and paraview
load it from there with PV_PLUGIN_PATH, or by LoadPlugin. Run by ctest (see CMakeLists.txt)
with the build tree and the programs in the environment."""
import os
import re
import shutil
import subprocess

import pytest

from xvfb_display import virtual_display

HERE = os.path.dirname(os.path.abspath(__file__))
ENV = os.environ
BUILD = ENV.get("MLR_BUILD_DIR")
LIBDIR = ENV.get("MLR_INSTALL_LIBDIR", "lib")
SUBDIR = ENV.get("MLR_PARAVIEW_PLUGIN_SUBDIR", "paraview-5.11/plugins")
NAME = "MovingLightRadiosity"


def run(command, env=None, timeout=180):
    result = subprocess.run([str(c) for c in command], capture_output=True, text=True,
                            timeout=timeout, env=env)
    report = (f"$ {' '.join(map(str, command))}\nexit code {result.returncode}\n"
              f"--- stdout\n{result.stdout}\n--- stderr\n{result.stderr}")
    return result, report


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    if not BUILD or not os.path.isdir(BUILD):
        pytest.fail(f"set MLR_BUILD_DIR to the build tree (now {BUILD!r})")
    prefix = tmp_path_factory.mktemp("prefix")
    result, report = run([ENV.get("MLR_CMAKE", "cmake"), "--install", BUILD, "--prefix", prefix])
    assert result.returncode == 0, report
    folder = prefix / LIBDIR / SUBDIR
    return {"prefix": prefix, "folder": folder, "plugin": folder / NAME / f"{NAME}.so"}


def environment(**extra):
    env = {k: v for k, v in ENV.items() if k not in ("PV_PLUGIN_PATH", "PYTHONPATH")}
    env.update({k: str(v) for k, v in extra.items()})
    return env


def test_plugin_is_in_paraviews_layout(installed):
    assert installed["plugin"].is_file(), \
        f"no {installed['plugin']}; the prefix holds {sorted(p.name for p in installed['folder'].parent.iterdir())}"


def test_plugin_finds_its_library_in_the_prefix(installed):
    result, report = run(["ldd", installed["plugin"]])
    assert result.returncode == 0, report
    found = re.search(r"libMovingLightRadiosityFilters\.so\S*\s+=>\s+(\S+)", result.stdout)
    assert found, "ldd does not resolve libMovingLightRadiosityFilters:\n" + report
    library = os.path.realpath(found.group(1))
    assert library.startswith(os.path.realpath(installed["prefix"])), \
        f"the installed plugin uses {library}, outside the install prefix:\n" + report


@pytest.mark.parametrize("program", ["pvbatch", "pvpython"])
def test_pv_plugin_path_loads_the_installed_plugin(installed, program):
    executable = ENV.get("MLR_" + program.upper(), program)
    command = [executable] + (["--force-offscreen-rendering"] if program == "pvbatch" else [])
    result, report = run(command + [os.path.join(HERE, "plugin_loads.py")],
                         env=environment(PV_PLUGIN_PATH=installed["folder"],
                                         MLR_EXPECT_PLUGIN=installed["plugin"]))
    assert result.returncode == 0, report


def test_load_plugin_loads_the_installed_plugin(installed):
    result, report = run([ENV.get("MLR_PVPYTHON", "pvpython"), os.path.join(HERE, "plugin_loads.py")],
                         env=environment(MLR_LOAD_PLUGIN=installed["plugin"],
                                         MLR_EXPECT_PLUGIN=installed["plugin"]))
    assert result.returncode == 0, report


def test_paraview_gui_loads_the_installed_plugin(installed, tmp_path):
    if not shutil.which("Xvfb"):
        pytest.skip("Xvfb is not installed")
    report_file = tmp_path / "report.txt"
    # --dr: no user settings read or written, so earlier sessions cannot load the plugin.
    with virtual_display() as display:
        result, report = run([ENV.get("MLR_PARAVIEW", "paraview"), "--dr",
                              f"--script={os.path.join(HERE, 'plugin_loads.py')}"],
                             env=environment(PV_PLUGIN_PATH=installed["folder"],
                                             MLR_EXPECT_PLUGIN=installed["plugin"],
                                             MLR_REPORT=report_file, MLR_TEST_DIR=HERE,
                                             DISPLAY=display))
    text = report_file.read_text() if report_file.exists() else "(no report: the script did not run)"
    assert result.returncode == 0 and text.strip() == "OK", f"{text}\n{report}"


def test_a_cxx_program_builds_on_the_installed_package(installed, tmp_path):
    """Examples/cxx finds the VTK module with find_package(MovingLightRadiosity) in the
    prefix, builds, and solves the Cornell box with it."""
    cmake = ENV.get("MLR_CMAKE", "cmake")
    source = os.path.join(HERE, os.pardir, os.pardir, "Examples", "cxx")
    build = tmp_path / "example"
    result, report = run([cmake, "-S", source, "-B", build, "-G", "Ninja",
                          f"-DCMAKE_PREFIX_PATH={installed['prefix']}"], env=environment())
    assert result.returncode == 0, report
    result, report = run([cmake, "--build", build], env=environment())
    assert result.returncode == 0, report
    data = os.path.join(HERE, os.pardir, os.pardir, "Data")
    result, report = run([build / "cornell_frame", data, "5000"], env=environment())
    assert result.returncode == 0, report
    assert re.search(r"^12116 elements, mean red radiosity \d+\.\d+ W/m\^2 in frame 15$",
                     result.stdout, re.M), report
