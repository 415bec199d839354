// Pictures of the animation: what a camera in front of the scene sees in each frame.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <sys/types.h>

class vtkPolyData;

namespace mlr::cli
{

/**
 * Renders the filter's Elements output as seen by a fixed camera on the -z side looking
 * along +z (y up), framing the front of the scene's bounding box like the Cornell box camera.
 * Surfaces are unlit: the radiosity of a diffuse surface is what the eye sees, interpolated
 * between elements within each smooth surface and mapped to colour with one exposure for the
 * whole animation so that frames compare. The light is drawn
 * white at its position in the frame. Needs an X display (ParaView's VTK renders with GLX).
 */
class FrameRenderer
{
public:
  /// `light` is the Light input (none when the scene's own surfaces emit); `bounds` those of
  /// the scene.
  /// With `up` (the zenith of a scene lit by the sun), an aerial view instead: from above a
  /// corner of the bounding box, looking at its centre, `up` pointing up in the picture.
  FrameRenderer(vtkPolyData* light, const double bounds[6], const double* up = nullptr);
  ~FrameRenderer();
  FrameRenderer(const FrameRenderer&) = delete;
  FrameRenderer& operator=(const FrameRenderer&) = delete;

  /// A bright but not extreme radiosity of the frame (W/m^2): the 99th percentile of the
  /// luminance of `Radiosity` over its cells.
  static double brightLevel(vtkPolyData* elements);

  /// Maps `brightLevel` (the largest over all frames) to near white.
  void setBrightLevel(double radiosity);

  /// Renders one frame, the light moved by `lightTranslation`, into a PNG file.
  /// Throws std::runtime_error when the picture cannot be written.
  void render(vtkPolyData* elements, const double lightTranslation[3],
    const std::filesystem::path& png);

private:
  struct Pipeline;
  std::unique_ptr<Pipeline> Internals;
};

/**
 * The X display the pictures are rendered on: $DISPLAY when it is set, else a private Xvfb
 * server started here and stopped by the destructor. The project's one way to get a display
 * off-screen, as Testing/Plugin/xvfb_display.py does it for the tests and the examples: a
 * display number drawn among thousands (the X server refuses one in use by its lock file),
 * -displayfd to know when it accepts clients, and -noreset, because ParaView's VTK opens a
 * first X connection and closes it before the render window opens its own, and a resetting
 * server drops a connection that arrives meanwhile. The server dies with this process even
 * when it is killed.
 */
class PictureDisplay
{
public:
  /// Throws std::runtime_error when there is no DISPLAY and Xvfb is not installed: call it
  /// before the solve, so that a run that cannot render fails at once.
  static void checkAvailable();

  /// Sets DISPLAY for this process, starting Xvfb when needed. Throws std::runtime_error.
  PictureDisplay();
  ~PictureDisplay();
  PictureDisplay(const PictureDisplay&) = delete;
  PictureDisplay& operator=(const PictureDisplay&) = delete;

  /// The display's name (":1234").
  const std::string& name() const { return this->Name; }

private:
  std::string Name;
  pid_t Server = -1; ///< the Xvfb started here, or -1
};

} // namespace mlr::cli
