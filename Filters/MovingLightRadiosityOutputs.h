// From Core's scene and solution to the filter's VTK outputs: the meshes (built once per
// solve), the arrays of one frame (built per time request) and the statistics.
#pragma once

#include "Scene.h"
#include "Solver.h"

#include "vtkSmartPointer.h"
#include "vtkType.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

class vtkCellData;
class vtkFieldData;
class vtkPointData;
class vtkPolyData;

namespace mlr::vtkoutputs
{

/// Bytes of the outputs of a scene of `elements` elements on `points` points: the element and
/// patch meshes kept with the solution, and the arrays of the frame shown (each time request
/// builds them again).
std::uint64_t estimateOutputMemory(std::size_t elements, std::size_t points);

/// The patch triangles (on the first `cornerCount` points of the scene, the patch corners)
/// with `Reflectance`.
vtkSmartPointer<vtkPolyData> patchMesh(const Scene& scene, std::size_t cornerCount);

/// Adds `Radiosity`, `DirectRadiosity` and `IndirectRadiosity` of each element's lit side in
/// `frame`, and `RadiosityFront`/`RadiosityBack` when `twoSided` (see addDisplayArrays for the
/// rest of a frame's Elements).
void addElementRadiosity(
  const Solution& solution, std::size_t frame, bool twoSided, vtkCellData* cellData);

/// The side of each patch that received more power over the animation, as the solve chose
/// it (Solution::patchLitSide), for every patch.
std::vector<Side> patchLitSides(const Solution& solution);

/// Adds `Radiosity`, the patch shooting solution of each patch's lit side in `frame`.
void addPatchRadiosity(const Solution& solution, const std::vector<Side>& litSides,
  std::size_t frame, vtkCellData* cellData);

/// One single-value array per statistic (counts, seconds, reuse modes), plus the predicted
/// speed-up of full reuse over classic for these frames, k and lambda (paper eq. 4), and
/// the strings PowerUnits ("W") and RadiosityUnits ("W/(scene unit)^2").
vtkSmartPointer<vtkFieldData> statisticsFieldData(
  const SolverStatistics& statistics, const SolverOptions& options);

/// The arrays of field data that change with the frame: `FrameIndex`, `LightPosition` (the
/// light's centroid) and `LightTranslation` (from the Light input to this frame), and
/// `SolveCount`, the number of solves so far.
void addFrameFieldData(vtkFieldData* fieldData, std::size_t frame, const Vec3& lightPosition,
  const Vec3& lightTranslation, std::int64_t solveCount);

// ------------------------------------------------------------------------------------------
// Display: colours a screen can show, smooth shading and the light itself.

/// Luminance of linear sRGB/Rec. 709 primaries.
double luminance(const Rgb& rgb);

/// The ACES filmic tone curve as fitted by K. Narkowicz (2015), per channel: maps an exposed
/// linear value x >= 0 to [0, 1], x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), clamped.
double acesFilmic(double x);

/// The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1], as 0..255.
unsigned char srgbByte(double linear);

/// The display colour of a radiosity: multiplied by `exposureScale` (2^EV), tone mapped with
/// acesFilmic per channel and sRGB-encoded.
std::array<unsigned char, 3> displayColor(const Rgb& radiosity, double exposureScale);

/// The exposure, in EV, that maps the 99th percentile of the lit-side luminance over every
/// element and frame of `solution` to AutoExposureTarget, so that one exposure serves the
/// whole animation (frames stay comparable). Computed from a histogram of log2 luminance in
/// steps of 1/64 EV; 0 when nothing is lit.
double autoExposure(const Solution& solution);

/// The exposed value the 99th percentile maps to: acesFilmic(1) = 0.80 (sRGB 231 of 255),
/// bright but short of white, so that brighter spots (under the light) keep some gradation.
constexpr double AutoExposureTarget = 1.0;

/**
 * The element mesh prepared for smooth shading: each scene point is split into one point
 * per group of elements that meet there across smooth edges, so that averaging at the points
 * never blends across a crease (lit-side normals more than FeatureAngle apart), between
 * materials (different reflectance) or between the lit sides of a thin wall. Cells keep the
 * order (and PatchId) of Scene::elementTriangles().
 */
struct SmoothShading
{
  /// The output point of each element corner, 3 per element.
  std::vector<vtkIdType> cornerPoints;
  /// The scene point each output point was split from.
  std::vector<std::uint32_t> scenePoints;
  /// 1 / (sum of the areas of the elements around each output point).
  std::vector<double> inverseArea;
  /// The area of each element, its weight at its corners.
  std::vector<double> elementAreas;
};

/// Creases sharper than this (degrees between lit-side normals) split the points.
constexpr double FeatureAngle = 30.0;

SmoothShading smoothShading(const Scene& scene, const Solution& solution);

/// The element triangles on the split points of `shading`, with `Reflectance` and `PatchId`
/// (cell data) and `ScenePointId` (point data): everything of the Elements output that does
/// not depend on the frame.
vtkSmartPointer<vtkPolyData> smoothElementMesh(const Scene& scene, const SmoothShading& shading);

/// Adds the display arrays of `frame`: cell `Color` from the cells' lit-side Radiosity, point
/// `Radiosity` (area-weighted over the cells around each point) and point `Color`, and makes
/// `Color` the active scalars of both. `exposureScale` is 2^(automatic + user exposure).
void addDisplayArrays(const Solution& solution, const SmoothShading& shading, std::size_t frame,
  double exposureScale, vtkPointData* pointData, vtkCellData* cellData);

/// Adds `AutoExposure` and `Exposure` (EV) and `ExposureScale`, 2^(AutoExposure + Exposure),
/// the factor applied to radiosity before the tone map.
void addExposureFieldData(vtkFieldData* fieldData, double autoExposure, double exposure);

/// A rigid motion of the light from its own frame (the Light input's coordinates) into the
/// scene in one frame: x -> rotation * x + translation, rotation row-major.
struct LightTransform
{
  std::array<std::array<double, 3>, 3> rotation{ { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } } };
  Vec3 translation;
};

/// The light's polygons, given in its own frame, posed by `transform`, with the cell array
/// `Power` (RGB, W): each polygon's share of `power`, by area, so that they sum to it. Every
/// light pose of the Light output goes through here.
vtkSmartPointer<vtkPolyData> posedLight(const std::vector<std::vector<Vec3>>& polygons,
  const LightTransform& transform, const Rgb& power);

} // namespace mlr::vtkoutputs
