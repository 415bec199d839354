// What a viewer sees: display colours (exposure, a filmic tone curve, sRGB), smooth shading
// on points split at creases, and the exposure in field data. The filter's Elements output
// and the command line's pictures both show these colours.
#pragma once

#include "MovingLightRadiosityOutputs.h"
#include "SurfaceRegions.h"

#include <array>
#include <cstdint>
#include <vector>

class vtkCellData;
class vtkPointData;

namespace mlr::vtkoutputs
{

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

/// The histogram autoExposure counts, with the unlit values and all values as its last two
/// entries: histograms of frames apart (ranks that hold different frames) add up to theirs.
std::vector<std::uint64_t> exposureHistogram(const Solution& solution);

/// autoExposure from the sum of the exposureHistogram of every frame.
double exposureOf(const std::vector<std::uint64_t>& histogram);

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

/// Creases sharper than this (degrees between lit-side normals) split the points: the angle
/// that ends the surfaces whose elements show one side (Scene::patchRegion).
constexpr double FeatureAngle = CreaseAngleDegrees;

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

/// The area-weighted mean, at each point of `shading`, of one value per element.
std::vector<Rgb> pointMeans(const SmoothShading& shading, const std::vector<Rgb>& elementValues);

/**
 * Adds, to cells and points, `Irradiance` (RGB, W/(scene unit)^2: the light arriving on each
 * element's lit side in `frame`, direct and indirect, the element's own emission excluded;
 * at points the area-weighted mean, as point `Radiosity`) and `Illuminance` (one component,
 * lm/(scene unit)^2, lx for a scene in metres): `luminousEfficacy` (lm/W) times the
 * luminance of `Irradiance` (Documentation/Method.md, section 15). With `twoSided`, also the
 * cell arrays `IrradianceFront`, `IrradianceBack`, `IlluminanceFront` and `IlluminanceBack`
 * of both sides, as RadiosityFront and RadiosityBack: a panel shows one side for the whole
 * animation, and the frames that light its other side must still say how much arrives there.
 */
void addIrradianceArrays(const Solution& solution, const SmoothShading& shading, std::size_t frame,
  double luminousEfficacy, bool twoSided, vtkPointData* pointData, vtkCellData* cellData);

/// Adds `AutoExposure` and `Exposure` (EV) and `ExposureScale`, 2^(AutoExposure + Exposure),
/// the factor applied to radiosity before the tone map.
void addExposureFieldData(vtkFieldData* fieldData, double autoExposure, double exposure);

} // namespace mlr::vtkoutputs
