// The filter's Sensors: from the Sensors input's points and normals to Core's sensors, and
// from their solution to the Sensors output (per frame Irradiance and Illuminance, and the
// daylight metrics over the run).
#pragma once

#include "Sensors.h"

#include "vtkSmartPointer.h"

#include <cstddef>
#include <vector>

class vtkFieldData;
class vtkPointData;
class vtkPointSet;
class vtkPolyData;

namespace mlr::vtksensors
{

/// The points of the Sensors input with their point array `Normals` (3 components; the
/// active normals when no array has that name). Throws mlr::Error naming the Sensors input
/// when the normals are missing or of the wrong shape, and checkSensors' errors.
SensorSet sensorsFromPoints(vtkPointSet* input);

/// How the run's time steps are read for the metrics: the solved frame each step shows, its
/// luminous efficacy (lm/W, as the element arrays take it) and that of its direct sun.
struct MetricSteps
{
  std::vector<std::size_t> frame;
  std::vector<double> efficacy, sunEfficacy;
  double hoursPerStep = 1;
  double autonomyThreshold = 300;
};

/**
 * The Sensors output without its per-frame arrays: the sensor points as vertices with
 * `Normals` (unit) and the metrics over the time steps, constant over time:
 * `DaylightAutonomy`, `UDILow`, `UDIUseful`, `UDIHigh` (shares of the steps) and
 * `DirectSunHours` (hours).
 */
vtkSmartPointer<vtkPolyData> sensorMesh(
  const SensorSet& sensors, const SensorSolution& solution, const MetricSteps& steps);

/// Adds `Irradiance` (RGB, W/(scene unit)^2) and `Illuminance` (efficacy times its
/// luminance) of `frame`, Illuminance active, and when the solve ran in batches their
/// standard errors `IrradianceStdError` (RGB) and `IlluminanceStdError` (efficacy times the
/// luminance of IrradianceStdError).
void addSensorArrays(
  const SensorSolution& solution, std::size_t frame, double efficacy, vtkPointData* pointData);

/// Adds the sensors' ray counts and time: `SensorShadowRays`, `SensorGatheringRays` (counts)
/// and `SecondsSensors`; when the solve ran in batches, per frame the median and 95th
/// percentile of the lit sensors' relative error (sensorFrameError) and their count:
/// `SensorRelativeErrorMedian`, `SensorRelativeErrorP95`, `LitSensors`.
void addSensorStatistics(vtkFieldData* fieldData, const SensorSolution& solution);

} // namespace mlr::vtksensors
