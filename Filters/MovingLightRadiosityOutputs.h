// From Core's scene and solution to the filter's VTK outputs: the meshes (built once per
// solve), the arrays of one frame (built per time request) and the statistics.
#pragma once

#include "Scene.h"
#include "Solver.h"

#include "vtkSmartPointer.h"

#include <cstddef>
#include <cstdint>
#include <vector>

class vtkCellData;
class vtkFieldData;
class vtkPolyData;

namespace mlr::vtkoutputs
{

/// Bytes of the outputs of a scene of `elements` elements on `points` points: the element and
/// patch meshes kept with the solution, and the arrays of the frame shown (each time request
/// builds them again).
std::uint64_t estimateOutputMemory(std::size_t elements, std::size_t points);

/// The element triangles with `Reflectance` and `PatchId`: everything of the Elements output
/// that does not depend on the frame.
vtkSmartPointer<vtkPolyData> elementMesh(const Scene& scene);

/// The patch triangles (on the first `cornerCount` points of the scene, the patch corners)
/// with `Reflectance`.
vtkSmartPointer<vtkPolyData> patchMesh(const Scene& scene, std::size_t cornerCount);

/// Adds `Radiosity`, `DirectRadiosity` and `IndirectRadiosity` of each element's lit side in
/// `frame`, and `RadiosityFront`/`RadiosityBack` when `twoSided`.
void addElementRadiosity(
  const Solution& solution, std::size_t frame, bool twoSided, vtkCellData* cellData);

/// The side of each patch that received more power over the animation (the patch-level
/// counterpart of Solution::litSide).
std::vector<Side> patchLitSides(const Solution& solution);

/// Adds `Radiosity`, the patch shooting solution of each patch's lit side in `frame`.
void addPatchRadiosity(const Solution& solution, const std::vector<Side>& litSides,
  std::size_t frame, vtkCellData* cellData);

/// One single-value array per statistic (counts, seconds, reuse modes), plus the predicted
/// speed-up of full reuse over classic for these frames, k and lambda (paper eq. 4).
vtkSmartPointer<vtkFieldData> statisticsFieldData(
  const SolverStatistics& statistics, const SolverOptions& options);

/// The arrays of field data that change with the frame: `FrameIndex`, `LightPosition` (the
/// light's centroid) and `LightTranslation` (from the Light input to this frame), and
/// `SolveCount`, the number of solves so far.
void addFrameFieldData(vtkFieldData* fieldData, std::size_t frame, const Vec3& lightPosition,
  const Vec3& lightTranslation, std::int64_t solveCount);

} // namespace mlr::vtkoutputs
