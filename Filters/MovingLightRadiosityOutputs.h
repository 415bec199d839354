// From Core's scene and solution to the filter's VTK outputs: the meshes (built once per
// solve), the arrays of one frame (built per time request) and the statistics.
#pragma once

#include "Scene.h"
#include "Solver.h"

#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkNew.h"
#include "vtkSmartPointer.h"
#include "vtkType.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

class vtkAbstractArray;
class vtkCellData;
class vtkPointData;
class vtkPolyData;

namespace mlr::vtkoutputs
{

/// A named 3-component array with components R, G, B: floats for physical values, unsigned
/// chars for display colours.
template <typename ArrayType = vtkFloatArray>
vtkSmartPointer<ArrayType> rgbArray(const char* name, std::size_t tuples)
{
  auto array = vtkSmartPointer<ArrayType>::New();
  array->SetName(name);
  array->SetNumberOfComponents(3);
  array->SetComponentName(0, "R");
  array->SetComponentName(1, "G");
  array->SetComponentName(2, "B");
  array->SetNumberOfTuples(static_cast<vtkIdType>(tuples));
  return array;
}

void setRgb(vtkFloatArray* array, std::size_t i, const Rgb& value);

/// Adds a one-value array `name` to `fieldData`.
template <typename ArrayType, typename Value>
void addValue(vtkFieldData* fieldData, const char* name, Value value)
{
  vtkNew<ArrayType> array;
  array->SetName(name);
  array->InsertNextValue(value);
  fieldData->AddArray(array);
}

/// Bytes of the outputs of a scene of `elements` elements on `points` points: the element and
/// patch meshes kept with the solution, and the arrays of the frame shown (each time request
/// builds them again).
std::uint64_t estimateOutputMemory(std::size_t elements, std::size_t points);

/// The patch triangles (on the first `cornerCount` points of the scene, the patch corners)
/// with `Reflectance`.
vtkSmartPointer<vtkPolyData> patchMesh(const Scene& scene, std::size_t cornerCount);

/// The cell of `scene` nearest each triangle's centroid (given by `triangles` on `points`):
/// the input cell a patch or an element was remeshed from, -1 for an empty scene.
std::vector<vtkIdType> nearestCells(
  vtkPolyData* scene, const std::vector<Vec3>& points, const std::vector<Triangle>& triangles);

/**
 * The user's own cell arrays of `input` (the Scene as solved) that passSceneCellArrays gives
 * the meshes: a zone, a MaterialId. Left out: the arrays the meshes have (Reflectance,
 * PatchId) or a frame writes (a scene that is an earlier output would keep a stale
 * Radiosity), the filter's own MovingLightRadiosity* arrays, VTK's vtk* ones
 * (vtkOriginalCellIds, vtkGhostType: how the input was split, not what it is, so that any
 * number of ranks gives the serial arrays), and arrays of another length than the cells,
 * each with a warning in `warnings`.
 */
std::vector<vtkAbstractArray*> sceneCellArraysToPass(
  vtkPolyData* input, std::vector<std::string>* warnings = nullptr);

/// The bytes one cell holds of `arrays` (strings taken at 32 bytes a value).
std::uint64_t bytesPerCell(const std::vector<vtkAbstractArray*>& arrays);

/**
 * Gives each element of `elements` and patch of `patches` (the meshes of `scene`) the values
 * of `passed` (sceneCellArraysToPass) on its nearest cell of `input`, and the field data
 * MaterialNames beside a MaterialId, as vtkProbeFilter passes a source's arrays: remeshing
 * merges input cells, so an element has no input cell of its own.
 */
void passSceneCellArrays(vtkPolyData* input, const std::vector<vtkAbstractArray*>& passed,
  const Scene& scene, vtkPolyData* elements, vtkPolyData* patches);

/// Adds `Radiosity`, `DirectRadiosity` and `IndirectRadiosity` of each element's lit side in
/// `frame`, and `RadiosityFront`/`RadiosityBack` when `twoSided` (see addDisplayArrays for the
/// rest of a frame's Elements).
void addElementRadiosity(
  const Solution& solution, std::size_t frame, bool twoSided, vtkCellData* cellData);

struct SmoothShading;

/// With an error estimate (Solution::hasErrorEstimate), adds the standard errors of each
/// element's lit side in `frame`: `RadiosityStdError` and `IrradianceStdError` (RGB,
/// W/(scene unit)^2) and `IlluminanceStdError` (`luminousEfficacy` times the luminance of
/// `IrradianceStdError`) to the cells, and to the points as their area-weighted means over the
/// cells around each point (as point `Radiosity` is made); when `twoSided`, also each side's
/// to the cells (`RadiosityStdErrorFront`, `...Back`, and so for the others); nothing
/// without one.
void addStdErrorArrays(const Solution& solution, const SmoothShading& shading, std::size_t frame,
  double luminousEfficacy, bool twoSided, vtkPointData* pointData, vtkCellData* cellData);

/// With an error estimate, adds to `fieldData` the per-frame arrays (one value per solved frame)
/// `RelativeErrorMedian`, `RelativeErrorP95` and `LitElements`, and `ErrorBatches`,
/// `ErrorRounds`, `TargetRelativeError` and the string `StoppedBy`; nothing without one.
void addErrorFieldData(vtkFieldData* fieldData, const Solution& solution);

/// The side each patch shows, its surface's, as the solve chose it (Solution::patchLitSide),
/// for every patch.
std::vector<Side> patchLitSides(const Solution& solution);

/// Adds `Radiosity`, the patch shooting solution of each patch's lit side in `frame`.
void addPatchRadiosity(const Solution& solution, const std::vector<Side>& litSides,
  std::size_t frame, vtkCellData* cellData);

/// One single-value array per statistic (counts, seconds, reuse modes), plus the predicted
/// speed-up of full reuse over classic for these frames, k and lambda (paper eq. 4), and
/// the strings PowerUnits ("W"), RadiosityUnits and IrradianceUnits ("W/(scene unit)^2") and
/// IlluminanceUnits ("lm/(scene unit)^2").
vtkSmartPointer<vtkFieldData> statisticsFieldData(
  const SolverStatistics& statistics, const SolverOptions& options);

/// The arrays of field data that change with the frame: `FrameIndex`, `LightPosition` (the
/// light's centroid) and `LightTranslation` (from the Light input to this frame), and
/// `SolveCount`, the number of solves so far.
void addFrameFieldData(vtkFieldData* fieldData, std::size_t frame, const Vec3& lightPosition,
  const Vec3& lightTranslation, std::int64_t solveCount);

/// A rigid motion of the light from its own frame (the Light input's coordinates) into the
/// scene in one frame: x -> rotation * x + translation, rotation row-major.
struct LightTransform
{
  std::array<std::array<double, 3>, 3> rotation{ { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } } };
  Vec3 translation;
};

/// The light's polygons, given in its own frame, posed by `transform`, with the cell array
/// `Power` (RGB, W, doubles): each polygon's share of `power`, by area, so that they sum to
/// it. Every light pose of the Light output goes through here.
vtkSmartPointer<vtkPolyData> posedLight(const std::vector<std::vector<Vec3>>& polygons,
  const LightTransform& transform, const Rgb& power);

/// A point light in the Light output: one vertex at `position` with the cell array `Power`
/// (RGB, W, doubles) of `power`.
vtkSmartPointer<vtkPolyData> posedPointLight(const Vec3& position, const Rgb& power);

/// Adds the cell array `LuminousFlux` (lm) to a Light output: each cell's `Power` at
/// `efficacy` lm per W of luminance (0.2126 R + 0.7152 G + 0.0722 B).
void addLuminousFlux(vtkPolyData* light, double efficacy);

} // namespace mlr::vtkoutputs
