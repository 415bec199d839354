// mlr-benchmark's light-rig cases: a turning light, a panning spot and the sun over a town
// block, each full reuse against classic with errors against a high-N classic reference.
#pragma once

#include "LightSource.h"
#include "Scene.h"
#include "Solution.h"
#include "SolverOptions.h"
#include "SunPath.h"
#include "TownScenes.h"

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace mlr
{
struct PatchMesh;
}

namespace mlr::bench
{

/// The sun of the sun cases: 48 positions of 2024-06-21 in Paris, every 15 minutes from 8:00
/// to 19:45 (UTC+2), over the town block's north and up.
SunPathRequest sunOverTownRequest(const scenes::TownBlock& town);

struct RigCaseOptions
{
  std::uint64_t paths = 600000; ///< N, effective paths per frame
  std::size_t frames = 30;      ///< the turning light's and the panning spot's frames
  int threads = 0;
  /// k: gathering rays per frame = k N, in the solves and the reference alike.
  double gatheringRatio = 1;
  /// The reference is classic with this many times N paths per frame.
  int referenceFactor = 16;
  /// Where references are cached between runs; empty: computed in every run, never stored.
  std::string cacheDirectory = "output/benchmark-cache";
};

/**
 * A 1.15 m square light in the paper-scale room, fixed at the room's centre 0.7 m below the
 * ceiling, turning 90 degrees about the y axis over the frames (facing down towards the red
 * wall, then down towards the green one). Prints classic and full reuse: seconds, speed-up,
 * MSE at the middle and last frames. Returns the results as a JSON object.
 */
std::string runTurningLight(const RigCaseOptions& options);

/**
 * The town block of scenes::townBlock() under 48 sun positions (2024-06-21 at 48.85 N,
 * 2.35 E, 08:00 to 19:45 local time, UTC+2, every 15 minutes: symmetric about solar noon),
 * E = 1000 W/m^2. Prints classic and full reuse: seconds, seconds per frame, speed-up, MSE
 * at the first frame, the highest sun and the last frame. Returns the results as JSON.
 */
std::string runSunOverTown(const RigCaseOptions& options);

/**
 * The same room lit by a point light 0.3 m below the ceiling's centre with an IES LM-63-2002
 * spot (type C, rotationally symmetric: half intensity at 30 degrees, none from 50), parsed
 * with mlr::parseIes, panning 90 degrees about y over the frames: its beam crosses the room
 * from the red wall over the floor to the green one. Prints classic and full reuse: seconds,
 * ms per frame, speed-up, MSE at the first, middle and last frames and over all, and the
 * solver's shadow-ray rate beside bare Embree's. Returns the results as JSON.
 */
std::string runPanningSpot(const RigCaseOptions& options);

/// A classic solution at options.referenceFactor x N paths per frame and its own seed, from
/// the cache of the cases above when it holds it: every element's lit side and the total
/// radiosity there, [frame][element][channel].
struct ReferenceRadiosity
{
  std::uint64_t paths = 0;
  std::vector<std::uint8_t> litSide;
  std::vector<double> radiosity;
};
ReferenceRadiosity classicReference(const std::string& name, const PatchMesh& mesh,
  const Scene& scene, const LightRig& rig, const SolverOptions& base,
  const RigCaseOptions& options);
/// Errors against a classic reference of a rig, for the cases of other files.
struct ReferenceErrors
{
  std::uint64_t referencePaths = 0;
  double referenceSeconds = 0; ///< what the reference's solve took when it was computed
  bool cached = false;
  /// Per solution given, per frame of the rig: the MSE as the cases above measure it.
  std::vector<std::vector<double>> mse;
  std::vector<double> referenceMeanRadiosity; ///< per frame of the rig
};

/**
 * The MSE of each of `solutions` against classic at referenceFactor x N (another seed) of
 * `rig` on `mesh`, cached in c.cacheDirectory under `name` as the other cases' references:
 * solution i's frame frames[i][f] against the reference's frame f, for every frame f of `rig`.
 */
ReferenceErrors referenceErrors(const std::string& name, const PatchMesh& mesh, const Scene& scene,
  const LightRig& rig, const SolverOptions& options, const RigCaseOptions& c,
  const std::vector<std::pair<const Solution*, std::vector<std::size_t>>>& solutions);

} // namespace mlr::bench
