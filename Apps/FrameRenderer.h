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
 * Draws the filter's outputs as seen by a fixed camera on the -z side looking along +z (y up),
 * framing the front of the scene's bounding box like the Cornell box camera, as ParaView shows
 * them on Apply: the Elements coloured by their point array `Color` as it is (the filter's
 * exposure, tone curve and smooth-shading points), unlit, and the Light output's polygons
 * where the filter posed them, in the plugin's unlit yellow. Needs an X display (ParaView's VTK
 * renders with GLX).
 *
 * A closed room seen from outside shows only walls whose outer side no light reaches (the
 * colours are each element's lit side, so the near wall shows its inner side's light as if
 * it were the view into the room). With frames given to sampleLighting(), the camera looks
 * from inside instead when that shows much more of the lit sides: rays cast from the outside
 * camera and from points just past each surface the view's axis crosses (up to 4, each
 * looking along +z with a wider angle) count the surfaces whose side facing the camera is
 * lit in the sampled frames. The outside camera stays unless it sees under a fifth of the
 * picture lit and an inside one at least twice as much; then the inside camera nearest the
 * outside that sees at least 80% of the best one's share is taken (usually just inside the
 * near wall: the widest view of the room).
 */
class FrameRenderer
{
public:
  /// `bounds` are those of the scene. With `up` (the zenith of a scene lit by the sun), an
  /// aerial view instead: from above a corner of the bounding box, looking at its centre, `up`
  /// pointing up in the picture.
  explicit FrameRenderer(const double bounds[6], const double* up = nullptr);
  ~FrameRenderer();
  FrameRenderer(const FrameRenderer&) = delete;
  FrameRenderer& operator=(const FrameRenderer&) = delete;

  /// Before the first render(), without `up`: one frame's Elements (cell arrays
  /// RadiosityFront and RadiosityBack, or Radiosity for one-sided surfaces, less
  /// EmittedRadiosity), whose lit sides count in the choice of the camera. Call it for a few
  /// frames of the animation.
  void sampleLighting(vtkPolyData* elements);

  /// Where the camera looks from, chosen at the first render(): "outside" (the default) or
  /// "inside", with its position.
  struct View
  {
    bool inside = false;
    double position[3] = { 0, 0, 0 };
    double viewAngle = 0;                 ///< degrees
    double litOutside = 0, litInside = 0; ///< fractions of the rays that met a lit side
  };
  /// Chooses the camera from the samples now, if it was not yet chosen, and returns it.
  const View& chooseView();

  /// Renders one frame, the filter's Elements and Light outputs of that frame, into a PNG
  /// file. Throws std::runtime_error when the picture cannot be written.
  void render(vtkPolyData* elements, vtkPolyData* light, const std::filesystem::path& png);

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
