// The command line's sensors: --work-plane's grid over the scene's upward-facing floors, and
// the sensors' series beside the main output.
#pragma once

#include "CommandLine.h"

#include "vtkSmartPointer.h"

#include <filesystem>

class vtkPolyData;

namespace mlr::cli
{

/// Faces whose normal is within this angle of up carry the work plane (degrees).
constexpr double WorkPlaneToleranceDegrees = 5;

/**
 * Sensors facing `up` at `height` above every polygon of `scene` whose normal is within
 * WorkPlaneToleranceDegrees of `up`, on the lattice (i + 1/2) `spacing`, (j + 1/2) `spacing`
 * of two axes across `up` (x and y for a z up), at the lattice points inside the polygon seen
 * along `up`. Point array Normals. Throws InputError when no face faces up, and UsageError
 * when the grid would have more sensors than a solve accepts.
 */
vtkSmartPointer<vtkPolyData> workPlaneSensors(
  vtkPolyData* scene, const Triple& up, double height, double spacing);

/// Writes the Sensors output of one frame (points as vertices and their arrays) to `path`,
/// a .vtp file. Throws std::runtime_error when it cannot be written.
void writeSensorFrame(vtkPolyData* sensors, const std::filesystem::path& path);

} // namespace mlr::cli
