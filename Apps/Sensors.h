// The command line's sensors: --work-plane's grid over the scene's upward-facing floors, and
// the sensors' series beside the main output.
#pragma once

#include "CommandLine.h"

#include "vtkSmartPointer.h"

#include <filesystem>
#include <vector>

class vtkPolyData;

namespace mlr::cli
{

/// Faces whose normal is within this angle of up carry the work plane (degrees).
constexpr double WorkPlaneToleranceDegrees = 5;

/// Under daylight, a floor facing down looks for the sky from this many of its points, along
/// this many directions from each: as many rays as under lights, from 64 points to 16 lights.
constexpr std::size_t SkyProbes = 32;
constexpr int SkyDirections = 32;

/**
 * Sensors facing `up` at `height` above the scene's floors, on the lattice (i + 1/2)
 * `spacing`, (j + 1/2) `spacing` of two axes across `up` (x and y for a z up), at the lattice
 * points inside each floor polygon seen along `up`. Point array Normals.
 *
 * The floors are the polygons whose normal is within WorkPlaneToleranceDegrees of `up`. With
 * `lights` (where the lights are) or `daylight` (the sun or a sky light the scene) the floors
 * are also found by geometry, as the solve is two-sided: the polygons within that angle of down
 * that touch one another at one height are the floor of a room modelled with outward normals
 * when, under lights, one of their points sees a light from its upper side and has nothing lit
 * straight below it, and under daylight, one of their points sees the sky (along one of
 * SkyDirections directions from each of up to SkyProbes points) and none is a correctly
 * oriented room's ceiling: a polygon facing up at it straight below, more than `height` below,
 * with the work plane between them walled in or the space above the group open too (a ground
 * just under a room, or open ground under a room on stilts, is no room). Of such a floor, a
 * polygon with something less than `height` above each of its lattice points is the bottom of a
 * low solid touching it, and no floor. The lattice then adds the floors' points, and loses the
 * points of the polygons facing up whose point lies above such a floor while they lie below it
 * or at its level (the ground under a room standing on it), and its points over the polygons
 * facing up that have nothing above them, stand over such a floor, are not walled in by that
 * room's walls, seen from behind, `height` above them (a table under an opening in the roof is)
 * and, under lights, see no light (that room's roof). A correctly oriented room's polygons
 * facing down (ceilings, undersides, a shelf over a lit floor) find no floor, and its work
 * plane is the one of the polygons facing up alone, as without either. Warns when every sensor
 * lies above the scene while some polygon faces down and no floor was found among them. Throws
 * InputError when no polygon is a floor, and UsageError when the grid would have more sensors
 * than a solve accepts or than fit in `memoryLimit` bytes (0: the default limit) with their
 * results over `frames` frames.
 */
vtkSmartPointer<vtkPolyData> workPlaneSensors(vtkPolyData* scene, const Triple& up, double height,
  double spacing, const std::vector<Triple>& lights = {}, bool daylight = false,
  std::size_t frames = 1, std::uint64_t memoryLimit = 0);

/// Writes the Sensors output of one frame (points as vertices and their arrays) to `path`,
/// a .vtp file. Throws std::runtime_error when it cannot be written.
void writeSensorFrame(vtkPolyData* sensors, const std::filesystem::path& path);

} // namespace mlr::cli
