"""What the ParaView examples share: finding and loading the plugin, and the X display.

Run the examples with pvpython. Without an X display (DISPLAY unset) they start a private
Xvfb for the run, the way the tests and the command line do (Testing/Plugin/xvfb_display.py).
"""
import ctypes
import glob
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PLUGIN_NAME = "MovingLightRadiosity"


def default_plugin():
    """The plugin in the build tree: <build>/<libdir>/paraview-5.11/plugins/<Name>/<Name>.so."""
    build = os.environ.get("MLR_BUILD_DIR", os.path.join(ROOT, "build"))
    found = sorted(glob.glob(os.path.join(build, "lib*", "**", PLUGIN_NAME, PLUGIN_NAME + ".so"),
                             recursive=True))
    return found[0] if found else None


def hold_x_display():
    """Keeps one connection to the X server open for the whole run. ParaView connects to X,
    disconnects and connects again to render; an Xvfb server (xvfb-run) resets when its last
    client leaves and drops a connection arriving meanwhile, and pvpython then aborts with
    "bad X server connection" now and then. A client that stays prevents the reset."""
    if not os.environ.get("DISPLAY"):
        return None
    try:
        xlib = ctypes.CDLL("libX11.so.6")
    except OSError:
        return None
    xlib.XOpenDisplay.restype = ctypes.c_void_p
    xlib.XOpenDisplay.argtypes = [ctypes.c_char_p]
    return xlib.XOpenDisplay(None)


def require_display(parser, script):
    """Debian's ParaView renders through X only and would abort at the first picture, after
    the whole solve: without DISPLAY, start a private Xvfb that ends with this process, or
    refuse to start when Xvfb is not installed. Keep what it returns until the end."""
    if os.environ.get("DISPLAY"):
        return hold_x_display()
    sys.path.insert(0, os.path.join(ROOT, "Testing", "Plugin"))
    from xvfb_display import display_for_this_process
    try:
        os.environ["DISPLAY"] = display_for_this_process()
    except RuntimeError as error:  # Xvfb missing, or it did not start
        parser.error(f"no X display (DISPLAY is not set) and {error}; on a desktop, run "
                     f"pvpython {script} ... there")
    return hold_x_display()


def load_plugin(pv, parser, plugin=None):
    """Loads the plugin into paraview.simple unless PV_PLUGIN_PATH already did."""
    if not hasattr(pv, PLUGIN_NAME):
        plugin = plugin or default_plugin()
        if not plugin or not os.path.isfile(plugin):
            parser.error(f"no plugin {plugin or PLUGIN_NAME + '.so'}: build the project "
                         f"(cmake --build build) or give --plugin PATH")
        pv.LoadPlugin(plugin, remote=False)
        if not hasattr(pv, PLUGIN_NAME):
            sys.exit(f"{plugin} loaded, but it does not provide the {PLUGIN_NAME} filter")


def picture_view(pv, size, background=(0.0, 0.0, 0.0)):
    """A square render view without axes, for pictures of the animation."""
    view = pv.CreateRenderView()
    view.ViewSize = [size, size]
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    view.Background = list(background)
    return view


def save_pictures(pv, view, times, folder, size):
    """One picture per time step, folder/frame_0000.png ..., through the animation scene."""
    animation = pv.GetAnimationScene()
    animation.UpdateAnimationUsingDataTimeSteps()
    os.makedirs(folder, exist_ok=True)
    for index, t in enumerate(times):
        animation.AnimationTime = t
        pv.SaveScreenshot(os.path.join(folder, f"frame_{index:04d}.png"), view,
                          ImageResolution=[size, size])
