// From the filter's VTK inputs to Core's scene, light and trajectory. Bad input throws
// mlr::Error with a message that names the input port, the cell or the array to fix.
#pragma once

#include "MovingLight.h"
#include "Remeshing.h"
#include "Vec3.h"

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "vtkSmartPointer.h"

class vtkDataObject;
class vtkPointSet;
class vtkPolyData;

namespace mlr::vtkinputs
{

/// The input `port` (the Scene, the Light) as a vtkPolyData: a vtkPolyData as it is; the
/// surface of another data set (its polygons and the boundary faces of its volume cells, with
/// their cell and field data); the surfaces of a composite data set's leaves, appended, their
/// materials (MaterialId, MaterialNames) matched by name, and a cell array that not every leaf
/// has dropped with a warning in `warnings`, except the arrays of `fills` (the Scene's
/// reflectance and emission), which the leaves without them take with the value given, with a
/// warning naming those leaves. Null for no input. Throws mlr::Error, naming the port, for
/// data that has no surface (a table). A surface made here carries the input's cell and point
/// ids and its leaves' blocks, which the messages of the functions below give.
vtkSmartPointer<vtkPolyData> surfaceOf(vtkDataObject* data, const std::string& port,
  std::vector<std::string>& warnings,
  const std::vector<std::pair<std::string, double>>& fills = {});

/// The Scene's polygons (strips split into triangles) with one material each: reflectance
/// from the cell array named `reflectanceName` (1 or 3 components, each in [0, 1)) and
/// emission from the one named `emissionName` (1 or 3 components, W/m^2, >= 0), if present.
/// Recoverable oddities (ignored vertices and lines, no reflectance) are appended to
/// `warnings`. Points that no polygon or strip uses are left out of the soup. An empty soup means
/// there is nothing to light. Throws mlr::Error, before copying anything, when the copy is
/// estimated to need more than `memoryLimitBytes` (0: half the physical memory). Cells whose
/// `MaterialId` is `skipMaterial` (>= 0) are left out: they are the light.
PolygonSoup sceneSoup(vtkPolyData* scene, std::vector<std::string>& warnings,
  std::uint64_t memoryLimitBytes = 0, const std::string& reflectanceName = "Reflectance",
  const std::string& emissionName = "Emission", int skipMaterial = -1);

/// One light of the Light input: its polygons (strips split into triangles) in the light's
/// own frame, and its power from the cell array LightPower when there is one.
struct LightInput
{
  std::vector<std::vector<Vec3>> polygons;
  bool hasPower = false;
  Rgb power;
};

/// The Light's polygons grouped into lights by the integer cell array LightId, in increasing
/// LightId order (one light without it). Throws for a LightPower that differs within a light.
std::vector<LightInput> lightInputs(vtkPolyData* light);

/// A light taken out of the Scene: the polygons of one material.
struct MaterialLight
{
  int materialId = -1;
  LightInput light; ///< hasPower when the material emits: the sum of emission times area
};

/**
 * The Scene's polygons of the material named `material` (field data `MaterialNames`, cell
 * array `MaterialId`, as vtkRadiositySceneReader gives them), with the power they emit
 * (cell array `emissionName` times their area; pi Ke area for an OBJ material with Ke).
 * Throws mlr::Error listing the materials found when none is named so, and when the material
 * has no polygon.
 */
MaterialLight materialLight(
  vtkPolyData* scene, const std::string& material, const std::string& emissionName);

/// How many lights the Light input holds: its distinct LightId values, or 1 without them.
std::size_t lightCount(vtkPolyData* light);

/// Every light's per-frame poses, and the frame times (strictly increasing).
struct Trajectory
{
  std::vector<double> times;
  /// Per light: one input per frame, or one for a light that does not move.
  std::vector<std::vector<PoseInput>> lights;
  /// Per frame, from the point arrays SunAzimuth and SunElevation (degrees) when present.
  std::vector<double> sunAzimuth, sunElevation;
  /// Per frame, from the point arrays SkyDiffuseHorizontal and DirectNormalIrradiance (W/m^2)
  /// when present.
  std::vector<double> skyDiffuseHorizontal, directNormal;
  /// Per frame, from the point array DayOfYear (1 to 366) when present: the Perez sky's date.
  std::vector<int> dayOfYear;
};

/**
 * The Trajectory of `lights` lights. One light: the points in order, one per frame. Several:
 * one polyline per light in LightId order; a polyline of one point is a light that does not
 * move, and the others must have one point per frame. Point arrays: Time (frame times, else
 * 0, 1, ...), Normal (3 components), Orientation (4, quaternion w, x, y, z, wins over Normal),
 * Power (1 or 3, a factor on the light's power), SunAzimuth and SunElevation (passed on).
 */
Trajectory trajectoryFromPoints(vtkPointSet* trajectory, std::size_t lights = 1);

/// One light at `count` evenly spaced positions from `start` to `end`, at times 0, 1, ...
Trajectory straightTrajectory(const Vec3& start, const Vec3& end, int count);

/// The index of the time step at or below `time` (the first one if `time` is earlier).
std::size_t frameAtOrBelow(const std::vector<double>& times, double time);

} // namespace mlr::vtkinputs
