// From the filter's VTK inputs to Core's scene, light and trajectory. Bad input throws
// mlr::Error with a message that names the input port, the cell or the array to fix.
#pragma once

#include "Remeshing.h"
#include "Vec3.h"

#include <cstdint>
#include <string>
#include <vector>

class vtkPointSet;
class vtkPolyData;

namespace mlr::vtkinputs
{

/// The Scene's polygons (strips split into triangles) with one material each, read from the
/// cell array `Reflectance`. Recoverable oddities (ignored vertices and lines, no
/// `Reflectance`) are appended to `warnings`. An empty soup means there is nothing to light.
/// Throws mlr::Error, before copying anything, when the copy is estimated to need more than
/// `memoryLimitBytes` (0: half the physical memory).
PolygonSoup sceneSoup(
  vtkPolyData* scene, std::vector<std::string>& warnings, std::uint64_t memoryLimitBytes = 0);

/// The Light's polygons (strips split into triangles), in the light's own frame.
std::vector<std::vector<Vec3>> lightPolygons(vtkPolyData* light);

/// Light centroid positions, one per frame, and the frame times (strictly increasing).
struct Trajectory
{
  std::vector<Vec3> positions;
  std::vector<double> times;
};

/// The Trajectory's points in order, with times from the point array `Time` if present.
Trajectory trajectoryFromPoints(vtkPointSet* trajectory);

/// `count` evenly spaced positions from `start` to `end`, at times 0, 1, ..., count-1.
Trajectory straightTrajectory(const Vec3& start, const Vec3& end, int count);

/// The index of the time step at or below `time` (the first one if `time` is earlier).
std::size_t frameAtOrBelow(const std::vector<double>& times, double time);

} // namespace mlr::vtkinputs
