// Core's one entry point for an animation: scene polygons with materials and a light rig in,
// per-frame radiosity of every element out.
#pragma once

#include "Chunks.h"
#include "Remeshing.h"
#include "Scene.h"
#include "Sensors.h"
#include "Solver.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace mlr
{

struct Animation;

/// Receives frames [firstFrame, firstFrame + frames.frameCount()) of `animation` (its patches,
/// scene and warnings so far; its solution not yet) once they are final (ChunkFramesCallback).
using AnimationFramesCallback =
  std::function<void(const Animation& animation, std::size_t firstFrame, Solution& frames)>;

struct AnimationOptions
{
  RemeshOptions remeshing;
  SolverOptions solver;
  /// What the caller will allocate for its outputs, per element and per point of the element
  /// mesh: counted in the one memory check, before remeshing and again before solving.
  std::uint64_t outputBytesPerElement = 0;
  std::uint64_t outputBytesPerPoint = 0;
  /// Measuring points solved after the scene (none: no sensor work), their ray counts, and
  /// what the caller will allocate per sensor and frame for their outputs.
  SensorSet sensors;
  SensorOptions sensorOptions;
  std::uint64_t outputBytesPerSensorFrame = 0;
  /// When set, the frames are streamed: each chunk's finished frames go here as soon as they
  /// are solved and are freed after (Chunks.h), and Animation::solution keeps the statistics
  /// only. The memory policy then counts one chunk's frames, not all.
  AnimationFramesCallback chunkFrames;
  /// The chunks of frames the caller keeps of those chunkFrames gets, at most (the filter
  /// over ranks keeps all it gets, its cache of chunks some): the memory policy counts them
  /// (estimateChunkedMemory). 0: none beyond the chunk handed on.
  std::size_t keptStreamedChunks = 0;
  /// With chunkFrames: a figure of the first chunk's frames for every rank (Chunks.h).
  FirstChunkFigure firstChunkFigure;
  /// When set, remeshing's warnings go here one by one as soon as the scene is built, before
  /// the memory check and the solve (which may fail, run for hours or be stopped), instead of
  /// into Animation::warnings.
  std::function<void(const std::string& warning)> sceneWarning;
};

/// A solved animation: the patches, the scene built from them and every frame's radiosity.
struct Animation
{
  PatchMesh patches;
  Scene scene;
  Solution solution;
  /// The irradiance of options.sensors in every frame of the solution.
  SensorSolution sensors;
  RemeshStatistics remeshing;
  /// Recoverable oddities from remeshing (unless options.sceneWarning took them) and
  /// solving, for the caller to show.
  std::vector<std::string> warnings;
};

/**
 * Remeshes `soup` (its materials' reflectance and emission) and solves every frame lit by
 * `lights` and the scene's emissive surfaces. One memory policy covers the whole run: the
 * limit of options.solver.memoryLimitBytes (0: half the physical memory) is checked before
 * remeshing allocates (from the patch count it expects) and again before solving, with the
 * caller's outputs included. Throws mlr::Error naming what to fix and mlr::Cancelled.
 * Progress: remeshing takes the first 5%, solving the rest (with sensors, the sensors take the
 * last 5%). Sensors are checked before remeshing and solved once the scene is: they do not
 * change its radiosity. The frames are solved in chunks (solveInChunks) of
 * options.solver.framesPerChunk frames, or of the most frames the memory limit allows
 * (chooseFramesPerChunk): every frame at once when it fits.
 */
Animation solveAnimation(const PolygonSoup& soup, const LightRig& lights,
  const AnimationOptions& options, const ProgressCallback& progress = {});

} // namespace mlr
