// Pictures of the animation: what a camera in front of the scene sees in each frame.
#pragma once

#include <filesystem>
#include <memory>

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
  /// `light` is the Light input; `bounds` those of the scene.
  FrameRenderer(vtkPolyData* light, const double bounds[6]);
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

} // namespace mlr::cli
