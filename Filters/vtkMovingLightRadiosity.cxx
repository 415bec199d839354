#include "vtkMovingLightRadiosity.h"

#include "MovingLightRadiosityDisplay.h"
#include "MovingLightRadiosityInputs.h"
#include "MovingLightRadiosityOutputs.h"
#include "MovingLightRadiosityParallel.h"
#include "MovingLightRadiositySensors.h"
#include "ProgressForwarder.h"

#include "Animation.h"
#include "Chunks.h"
#include "Error.h"
#include "LuminaireTilt.h"
#include "MovingLight.h"
#include "Photometry.h"
#include "Plural.h"
#include "PointLight.h"
#include "Remeshing.h"
#include "Scene.h"
#include "Sky.h"
#include "Solver.h"

#include "vtkAppendPolyData.h"
#include "vtkCellData.h"
#include "vtkCommand.h"
#include "vtkDataObject.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointSet.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"
#include "vtkTimeStamp.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iomanip>
#include <limits>
#include <memory>
#include <new>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

static_assert(mlr::MaximumPathsPerFrame == 100000000000ULL,
  "keep the clamp of vtkMovingLightRadiosity::NumberOfPaths equal to Core's maximum");

/// The last solve: every frame of the animation, kept until an input or a property changes.
struct vtkMovingLightRadiosity::vtkInternals
{
  bool HasResult = false;
  /// Taken just before the inputs and properties were read for the solve.
  vtkTimeStamp SolveTime;
  std::vector<double> Times;
  /// The hours one frame stands for (DirectSunHours): the Trajectory's field data
  /// TimeStepHours, else the frames' median spacing.
  double HoursPerStep = 1;
  /// The lights with their poses, for the Light output and the frame's field data.
  mlr::LightRig Rig;
  /// Per frame, passed on from the Trajectory when it has them (degrees).
  std::vector<double> SunAzimuth, SunElevation;
  /// Per frame with a sky or the sun: the Perez efficacy of its daylight on a horizontal
  /// surface (lm/W).
  std::vector<double> DaylightEfficacy;
  /// Per frame with a sky or the sun: the Perez efficacy of the direct sun alone (lm/W).
  std::vector<double> SunEfficacy;
  /// The Sensors output without its frame's arrays (its metrics for SensorSteps' threshold
  /// and efficacies, these from SensorEfficacy where no daylight has its own), the sensors,
  /// their solution and the time steps the metrics count.
  vtkSmartPointer<vtkPolyData> SensorMesh;
  double SensorEfficacy = 0;
  mlr::SensorSet SensorPoints;
  mlr::SensorSolution Sensors;
  mlr::vtksensors::MetricSteps SensorSteps;
  // Display: what the colours of every frame need.
  mlr::vtkoutputs::SmoothShading Shading;
  double AutoExposure = 0;
  /// Taken when the properties were last found to match the solve: Exposure moves it on, as
  /// a new exposure needs no new solve (see SetExposure).
  vtkTimeStamp PropertiesTime;
  /// Null when the scene had nothing to light: the outputs are then empty.
  vtkSmartPointer<vtkPolyData> Elements;
  vtkSmartPointer<vtkPolyData> Patches;
  vtkSmartPointer<vtkFieldData> Statistics;
  mlr::Solution Solution;
  /// The frame Solution starts at: 0 but when chunks were streamed to the ChunkObserver,
  /// which leaves the last chunk's frames.
  std::size_t FirstFrame = 0;
  /// Several ranks: the frames this rank holds, in blocks (Solution then holds no frame).
  /// With FramesApart each rank holds the chunks it solved (streamed to the ChunkObserver,
  /// the last of them in Solution), outputs the whole of their time steps and an empty piece
  /// at the others'; else every rank holds every frame.
  std::vector<mlr::vtkparallel::FrameBlock> RankFrames;
  bool FramesApart = false;
  /// CachedChunks: the blocks of RankFrames are whole chunks, the last asked for first, and
  /// what solving a dropped chunk again takes is kept.
  std::shared_ptr<const mlr::Scene> ChunkScene;
  mlr::SolverOptions ChunkOptions;
  std::size_t FramesPerChunk = 0;
  std::vector<mlr::Side> FirstChunkLitSides, FirstChunkPatchLitSides;
  std::vector<std::uint64_t> ChunkBatches;
  int ChunksSolvedAgain = 0;

  /// Puts a chunk's frames first among the cached ones, dropping the oldest beyond `kept`
  /// but the chunk that holds frame WantedFrame: during the first solve, the time step asked
  /// for, which would otherwise be solved again at once.
  void cacheChunk(std::size_t first, mlr::Solution frames, std::size_t kept)
  {
    this->RankFrames.insert(this->RankFrames.begin(), { first, std::move(frames) });
    while (this->RankFrames.size() > kept)
    {
      auto oldest = std::prev(this->RankFrames.end());
      const bool wanted = this->WantedFrame >= oldest->first &&
        this->WantedFrame < oldest->first + oldest->frames.frameCount();
      this->RankFrames.erase(wanted ? std::prev(oldest) : oldest);
    }
  }
  std::size_t WantedFrame = std::numeric_limits<std::size_t>::max();
  std::vector<mlr::Side> PatchLitSides;
  bool TwoSided = true;

  /// Empties the result; the times of the last attempt are kept, as RequestData compares
  /// them with the MTimes to tell a failed attempt asked again from a changed one.
  void Clear()
  {
    const vtkTimeStamp solveTime = this->SolveTime;
    const vtkTimeStamp propertiesTime = this->PropertiesTime;
    *this = vtkInternals();
    this->SolveTime = solveTime;
    this->PropertiesTime = propertiesTime;
  }

  /// The last attempt failed (Failure says why), or was aborted on some rank (Aborted).
  bool Failed = false;
  bool Aborted = false;
  std::string Failure;

  // Several ranks: this rank outputs only the elements and patches that come from
  // its own input cells, and rank 0 the Light.
  bool Distributed = false;
  std::vector<vtkIdType> OwnedElements, OwnedPatches;
  bool OutputsLight = true;
};

vtkStandardNewMacro(vtkMovingLightRadiosity);

//------------------------------------------------------------------------------
vtkMovingLightRadiosity::vtkMovingLightRadiosity()
  : Internals(new vtkInternals)
{
  const mlr::SolverOptions defaults;
  this->LightPower[0] = this->LightPower[1] = this->LightPower[2] = 100.0;
  this->NumberOfPaths = static_cast<vtkIdType>(defaults.pathsPerFrame);
  this->GatheringRatio = defaults.gatheringRatio;
  this->FirstBounceSurvival = defaults.firstBounceSurvival;
  this->ReuseShooting = defaults.reuseShooting;
  this->BalanceFrames = defaults.balanceFrames;
  this->ReuseGathering = defaults.reuseGathering;
  this->PatchSize = 0.0;
  this->Seed = static_cast<int>(defaults.seed);
  this->NumberOfThreads = defaults.threads;
  this->TwoSided = defaults.twoSided;
  this->PathStart[0] = this->PathStart[1] = this->PathStart[2] = 0.0;
  this->PathEnd[0] = 1.0;
  this->PathEnd[1] = this->PathEnd[2] = 0.0;
  this->NumberOfPositions = 10;
  this->MemoryLimit = 0;
  this->FramesPerChunk = 0;
  this->ChunkOverlap = 0;
  this->CachedChunks = 0;
  this->SolveCount = 0;
  this->Exposure = 0.0;
  this->LuminousEfficacy = 179.0;
  this->LightType = AREA_LIGHT;
  this->SunIrradiance = 1000.0;
  this->SkyModel = NO_SKY;
  this->SkyDiffuseHorizontal = 100.0;
  this->Up[0] = 0.0;
  this->Up[1] = 0.0;
  this->Up[2] = 1.0;
  this->AimAtPoint = 0;
  this->AimPoint[0] = this->AimPoint[1] = this->AimPoint[2] = 0.0;
  this->SpotHalfAngle = 0.0;
  this->SpotSoftEdge = 0.0;
  this->LightFluxLumens = 0.0;
  this->LightFluxFromFile = false;
  this->ReflectanceArrayName = "Reflectance";
  this->EmissionArrayName = "Emission";
  this->LightPowerFromMaterial = 1;
  this->PathFromLightMaterial = 0;
  this->ErrorBatches = 16;
  this->TargetRelativeError = defaults.targetRelativeError;
  this->TimeLimit = defaults.timeLimitSeconds;
  this->DaylightAutonomyThreshold = 300.0;
  this->SensorRays = static_cast<int>(mlr::SensorOptions().hemisphereRays);

  this->SetNumberOfInputPorts(4);
  this->SetNumberOfOutputPorts(4);
  vtkNew<mlr::ProgressForwarder> progress;
  progress->Report = [this](double amount) { this->ReportProgress(amount); };
  this->SetProgressObserver(progress);
}

//------------------------------------------------------------------------------
void vtkMovingLightRadiosity::ReportProgress(double amount)
{
  // Nothing past an abort: neither the solve's last reports nor the executive's 1.0.
  if (this->ProgressStopped || this->AbortExecute)
  {
    return;
  }
  this->Progress = amount;
  this->InvokeEvent(vtkCommand::ProgressEvent, &amount);
}

//------------------------------------------------------------------------------
vtkMovingLightRadiosity::~vtkMovingLightRadiosity() = default;

namespace
{
/// Each sensor samples every area light with an eighth as many points as SensorRays, so that
/// one property sets the sensors' accuracy: 64 points at the default 512 rays, in a Latin
/// hypercube, leave about 2% of noise 1 to 3 light sizes away from a panel.
constexpr std::uint32_t SensorRaysPerLightSample = 8;

/// A numeric property's range, bounds included, and what to give when a value is outside.
struct PropertyRange
{
  const char* name;
  double low, high;
  const char* give;
  double (*value)(vtkMovingLightRadiosity*);
};

using Self = vtkMovingLightRadiosity;
constexpr double Most = std::numeric_limits<double>::max();
const PropertyRange PropertyRanges[] = {
  { "NumberOfPaths", 1, static_cast<double>(mlr::MaximumPathsPerFrame),
    "paths per frame from 1 to 100000000000 (600000 is typical)",
    [](Self* f) { return static_cast<double>(f->GetNumberOfPaths()); } },
  { "GatheringRatio", 0, 1000, "0 (no final gathering) up to 1000 (1 is typical)",
    [](Self* f) { return f->GetGatheringRatio(); } },
  { "FirstBounceSurvival", mlr::MinimumFirstBounceSurvival, 1,
    "a probability from 0.001 to 1 (0.25 is typical)",
    [](Self* f) { return f->GetFirstBounceSurvival(); } },
  { "PatchSize", 0, Most, "0 (about 3000 patches) or a positive length, in scene units",
    [](Self* f) { return f->GetPatchSize(); } },
  { "Seed", 0, VTK_INT_MAX, "0 or a positive integer",
    [](Self* f) { return static_cast<double>(f->GetSeed()); } },
  { "NumberOfThreads", 0, 1024, "0 (every core) or 1 to 1024",
    [](Self* f) { return static_cast<double>(f->GetNumberOfThreads()); } },
  { "NumberOfPositions", 1, 100000, "1 to 100000 light positions",
    [](Self* f) { return static_cast<double>(f->GetNumberOfPositions()); } },
  { "SunIrradiance", 0, Most,
    "0 (no direct sun) or an irradiance in W/m^2 (1000 at noon on a clear day)",
    [](Self* f) { return f->GetSunIrradiance(); } },
  { "SkyDiffuseHorizontal", 0, Most, "0 or an irradiance in W/m^2 (100 is typical)",
    [](Self* f) { return f->GetSkyDiffuseHorizontal(); } },
  { "SpotHalfAngle", 0, 180, "0 (no spot) up to 180 degrees",
    [](Self* f) { return f->GetSpotHalfAngle(); } },
  { "SpotSoftEdge", 0, 180, "0 (a hard edge) up to 180 degrees",
    [](Self* f) { return f->GetSpotSoftEdge(); } },
  { "LightFluxLumens", 0, mlr::MaximumLightPower,
    "0 (LightPower's watts) or a luminous flux in lm, at most 1e30",
    [](Self* f) { return f->GetLightFluxLumens(); } },
  { "MemoryLimit", 0, VTK_INT_MAX, "0 (half of the physical memory) or a limit in MiB",
    [](Self* f) { return static_cast<double>(f->GetMemoryLimit()); } },
  { "FramesPerChunk", 0, VTK_INT_MAX, "0 (MemoryLimit chooses) or at least 2",
    [](Self* f) { return static_cast<double>(f->GetFramesPerChunk()); } },
  { "ChunkOverlap", 0, static_cast<double>(mlr::MaximumChunkOverlap),
    "0 (FramesPerChunk/8) or a count of frames, at most FramesPerChunk/2",
    [](Self* f) { return static_cast<double>(f->GetChunkOverlap()); } },
  { "CachedChunks", 0, VTK_INT_MAX, "0 (every frame kept) or a count of chunks",
    [](Self* f) { return static_cast<double>(f->GetCachedChunks()); } },
  { "ErrorBatches", 1, static_cast<double>(mlr::MaximumErrorBatches),
    "1 (no error estimate) up to 4096 (16 is typical)",
    [](Self* f) { return static_cast<double>(f->GetErrorBatches()); } },
  { "Exposure", -20, 20, "-20 to 20 EV (0 is the automatic exposure)",
    [](Self* f) { return f->GetExposure(); } },
  { "SensorRays", mlr::MinimumHemisphereRays, mlr::MaximumSensorRays,
    "16 to 1000000 rays per sensor (512 is typical; fewer give a standard error that reads 0 "
    "when they all miss what lights the sensor)",
    [](Self* f) { return static_cast<double>(f->GetSensorRays()); } },
  { "DaylightAutonomyThreshold", 0, Most, "0 or an illuminance in lx (300 is typical)",
    [](Self* f) { return f->GetDaylightAutonomyThreshold(); } },
};
} // namespace

//------------------------------------------------------------------------------
bool vtkMovingLightRadiosity::GetPropertyRange(const char* name, double range[2])
{
  for (const PropertyRange& known : PropertyRanges)
  {
    if (name && std::string(name) == known.name)
    {
      range[0] = known.low;
      range[1] = known.high;
      return true;
    }
  }
  return false;
}

//------------------------------------------------------------------------------
template <typename T>
void vtkMovingLightRadiosity::SetKeepingTheSolve(T& property, T value)
{
  if (value == property)
  {
    return;
  }
  // The outputs must be built again, but from the cached solve: when the properties matched
  // the solve before this change, they still do after it.
  vtkInternals& cache = *this->Internals;
  const bool current = cache.HasResult && this->GetMTime() <= cache.PropertiesTime.GetMTime();
  property = value;
  this->Modified();
  if (current)
  {
    cache.PropertiesTime.Modified();
  }
}

//------------------------------------------------------------------------------
template <typename T>
void vtkMovingLightRadiosity::SetUnlessUsed(T& property, T value, bool unused)
{
  if (unused)
  {
    this->SetKeepingTheSolve(property, value);
  }
  else if (!(value == property))
  {
    property = value;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
void vtkMovingLightRadiosity::SetPathPoint(double* point, double x, double y, double z)
{
  // A connected Trajectory gives the positions: the path's ends wait unused, and dragging
  // their widget by mistake does not solve the animation again.
  const bool unused = this->GetNumberOfInputConnections(TRAJECTORY_PORT) > 0;
  const double given[3] = { x, y, z };
  for (int i = 0; i < 3; ++i)
  {
    this->SetUnlessUsed(point[i], given[i], unused);
  }
}

void vtkMovingLightRadiosity::SetPathStart(double x, double y, double z)
{
  this->SetPathPoint(this->PathStart, x, y, z);
}

void vtkMovingLightRadiosity::SetPathStart(const double start[3])
{
  this->SetPathStart(start[0], start[1], start[2]);
}

void vtkMovingLightRadiosity::SetPathEnd(double x, double y, double z)
{
  this->SetPathPoint(this->PathEnd, x, y, z);
}

void vtkMovingLightRadiosity::SetPathEnd(const double end[3])
{
  this->SetPathEnd(end[0], end[1], end[2]);
}

void vtkMovingLightRadiosity::SetNumberOfPositions(int positions)
{
  this->SetUnlessUsed(
    this->NumberOfPositions, positions, this->GetNumberOfInputConnections(TRAJECTORY_PORT) > 0);
}

void vtkMovingLightRadiosity::SetSunIrradiance(double irradiance)
{
  this->SetUnlessUsed(this->SunIrradiance, irradiance, this->LightType != DIRECTIONAL_LIGHT);
}

void vtkMovingLightRadiosity::SetSensorRays(int rays)
{
  this->SetUnlessUsed(this->SensorRays, rays, this->GetNumberOfInputConnections(SENSORS_PORT) == 0);
}

//------------------------------------------------------------------------------
void vtkMovingLightRadiosity::SetExposure(double exposure)
{
  this->SetKeepingTheSolve(this->Exposure, exposure);
}

//------------------------------------------------------------------------------
void vtkMovingLightRadiosity::SetLuminousEfficacy(double efficacy)
{
  // Without lumens to turn into watts the efficacy only turns irradiance into illuminance,
  // which the outputs do from the cached solve.
  if (this->LightFluxLumens > 0 ||
    (this->LightFluxFromFile && !this->LightDistributionFile.empty()))
  {
    if (efficacy != this->LuminousEfficacy)
    {
      this->LuminousEfficacy = efficacy;
      this->Modified();
    }
    return;
  }
  this->SetKeepingTheSolve(this->LuminousEfficacy, efficacy);
}

//------------------------------------------------------------------------------
void vtkMovingLightRadiosity::SetDaylightAutonomyThreshold(double threshold)
{
  // The metrics are recomputed from the cached solve when the output is built.
  this->SetKeepingTheSolve(this->DaylightAutonomyThreshold, threshold);
}

//------------------------------------------------------------------------------
void vtkMovingLightRadiosity::SetNumberOfThreads(int threads)
{
  // The solution is the same bits for any thread count: a solve kept is still the one asked
  // for. A solve that failed (its memory depends on the workers) runs again; so does one
  // whose rounds a TimeLimit cut (more threads run more of them), and one of kept chunks,
  // whose chunks solved again when shown take the threads of the solve.
  if (this->TimeLimit > 0 || this->CachedChunks > 0)
  {
    if (threads != this->NumberOfThreads)
    {
      this->NumberOfThreads = threads;
      this->Modified();
    }
    return;
  }
  this->SetKeepingTheSolve(this->NumberOfThreads, threads);
}

//------------------------------------------------------------------------------
int vtkMovingLightRadiosity::FillInputPortInformation(int port, vtkInformation* info)
{
  if (port == TRAJECTORY_PORT || port == SENSORS_PORT)
  {
    info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
    info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
    return 1;
  }
  // Any data set or composite of them, whole: its surface is taken (vtkinputs::surfaceOf).
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkDataObject");
  if (port == LIGHT_PORT)
  {
    // A directional light, or a scene whose surfaces emit, needs no Light.
    info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  }
  return 1;
}

namespace
{
/**
 * The first numeric property outside its range, as an error naming it, the value given and
 * what to give; empty when every one is in range. The properties are kept as given rather
 * than clamped as VTK's set-macros do, so that a mistake (0 paths, a negative seed, NaN) is
 * named instead of solving something else.
 */
std::string propertyOutOfRange(vtkMovingLightRadiosity* self)
{
  // Whole numbers (counts) with every digit, so that a value just over a bound shows it.
  const auto format = [](double value)
  {
    std::ostringstream s;
    if (std::abs(value) < 9e18 && value == std::floor(value))
    {
      s << static_cast<long long>(value);
    }
    else
    {
      s << std::setprecision(15) << value;
    }
    return s.str();
  };
  if (self->GetLightType() < Self::AREA_LIGHT || self->GetLightType() > Self::LUMINAIRE_LIGHT)
  {
    return "LightType is " + std::to_string(self->GetLightType()) +
      ": give 0 (Area), 1 (Directional), 2 (Point) or 3 (Luminaire)";
  }
  if (self->GetSkyModel() < Self::NO_SKY || self->GetSkyModel() > Self::PEREZ_SKY)
  {
    return "SkyModel is " + std::to_string(self->GetSkyModel()) +
      ": give 0 (none), 1 (uniform), 2 (CIE overcast), 3 (CIE clear) or 4 (Perez)";
  }
  const double efficacy = self->GetLuminousEfficacy();
  if (!(efficacy > 0 && efficacy <= 683))
  {
    return "LuminousEfficacy is " + format(efficacy) +
      " lm/W: give the light's luminous efficacy, above 0 and at most 683 lm/W (179 for white "
      "light)";
  }
  for (const PropertyRange& range : PropertyRanges)
  {
    const double value = range.value(self);
    if (!(value >= range.low && value <= range.high))
    {
      return std::string(range.name) + " is " + format(value) + ": give " + range.give;
    }
  }
  // The ranges above make both counts non-negative.
  return mlr::chunkSettingsProblem(static_cast<std::uint64_t>(self->GetFramesPerChunk()),
    static_cast<std::uint64_t>(self->GetChunkOverlap()), "FramesPerChunk", "ChunkOverlap");
}

/**
 * The error figures of streamed frames, by frame: the chunks hand them on with their frames,
 * and the animation's summary has none per frame. Over ranks each rank holds those of the
 * frames it received: a frame of a chunk one rank solved, or every frame when the ranks split
 * the paths (then alike on every rank).
 */
struct StreamedErrors
{
  std::vector<double> median, p95, lit;
  std::vector<double> received; ///< 1 for the frames this rank received

  void add(std::size_t first, const mlr::ErrorEstimateSummary& chunk)
  {
    const std::size_t count = std::min(chunk.relativeErrorP95.size(),
      std::min(chunk.relativeErrorMedian.size(), chunk.litElements.size()));
    this->resize(std::max(this->received.size(), first + count));
    for (std::size_t i = 0; i < count; ++i)
    {
      this->median[first + i] = chunk.relativeErrorMedian[i];
      this->p95[first + i] = chunk.relativeErrorP95[i];
      this->lit[first + i] = static_cast<double>(chunk.litElements[i]);
      this->received[first + i] = 1;
    }
  }

  void resize(std::size_t frames)
  {
    for (std::vector<double>* v : { &this->median, &this->p95, &this->lit, &this->received })
    {
      v->resize(frames, 0.0);
    }
  }

  /// Adds the animation's error field data with every frame's figures; nothing when a frame
  /// has none. `sum` (over ranks, collective) gives each rank the frames only another holds,
  /// exactly: a sum with zeros from the others, never of several ranks' values.
  void addTo(vtkFieldData* fieldData, const mlr::ErrorEstimateSummary& animation,
    std::size_t frames, const std::function<void(double*, std::size_t)>& sum)
  {
    this->resize(frames);
    std::vector<double> holders = this->received;
    if (sum)
    {
      sum(holders.data(), holders.size());
      std::vector<double> alone(3 * frames, 0.0);
      for (std::size_t f = 0; f < frames; ++f)
      {
        if (this->received[f] > 0 && holders[f] == 1)
        {
          alone[f] = this->median[f];
          alone[frames + f] = this->p95[f];
          alone[2 * frames + f] = this->lit[f];
        }
      }
      sum(alone.data(), alone.size());
      for (std::size_t f = 0; f < frames; ++f)
      {
        if (holders[f] == 1)
        {
          this->median[f] = alone[f];
          this->p95[f] = alone[frames + f];
          this->lit[f] = alone[2 * frames + f];
          this->received[f] = 1;
        }
      }
    }
    mlr::Solution summary;
    summary.errorEstimate = animation;
    summary.errorEstimate.relativeErrorMedian.clear();
    summary.errorEstimate.relativeErrorP95.clear();
    summary.errorEstimate.litElements.clear();
    for (std::size_t f = 0; f < frames; ++f)
    {
      if (!(this->received[f] > 0))
      {
        return;
      }
      summary.errorEstimate.relativeErrorMedian.push_back(this->median[f]);
      summary.errorEstimate.relativeErrorP95.push_back(this->p95[f]);
      summary.errorEstimate.litElements.push_back(static_cast<std::uint64_t>(this->lit[f]));
    }
    mlr::vtkoutputs::addErrorFieldData(fieldData, summary);
  }
};

/// The number of lights whose poses the Trajectory holds: the Light's LightId groups for
/// area lights, one for a directional or point light.
std::size_t lightsOf(vtkMovingLightRadiosity* self, vtkInformationVector* lightInput)
{
  if (self->GetLightType() != vtkMovingLightRadiosity::AREA_LIGHT || *self->GetLightMaterial())
  {
    return 1;
  }
  std::vector<std::string> ignored; // the solve reports them
  return mlr::vtkinputs::lightCount(
    mlr::vtkinputs::surfaceOf(vtkDataObject::GetData(lightInput, 0), "Light", ignored));
}

/// What an area or point light emits in `frame` (one pose for a light that does not move):
/// its power times the pose's factor, the Trajectory's Power and a TILT table's.
template <typename Light>
mlr::Rgb emittedPower(const Light& light, std::size_t frame)
{
  return light.power() * light.pose(light.frameCount() > 1 ? frame : 0).power;
}

/// "frame 5" or "frames 3, 5, 8", the first 8 and "..." after them.
std::string framesNamed(const std::vector<std::size_t>& frames)
{
  std::ostringstream s;
  s << (frames.size() == 1 ? "frame " : "frames ");
  for (std::size_t k = 0; k < frames.size() && k < 8; ++k)
  {
    s << (k ? ", " : "") << frames[k];
  }
  s << (frames.size() > 8 ? ", ..." : "");
  return s.str();
}

/// Whether the sun of frame `f` is below the horizon: by the Trajectory's SunElevation when
/// it has one (the Sun Path source's, whose Up may differ from the filter's: a Y-up scene's
/// source set to Up 0, 1, 0 beside the filter's default), else across `up`.
bool sunBelowHorizon(
  const mlr::vtkinputs::Trajectory& trajectory, std::size_t f, const mlr::Vec3& up)
{
  return f < trajectory.sunElevation.size()
    ? trajectory.sunElevation[f] < 0
    : mlr::dot(trajectory.lights.front()[f].position, up) < 0;
}

/// A sun below the horizon is night: its frames go dark, where the solve would light the
/// scene from below (its surfaces may be two-sided) and give those frames a share of the
/// mixture's paths. Warns of the frames whose sun this turned off (the Sun Path source
/// already gives its night frames Power 0), and of frames whose SunElevation disagrees with
/// `up`.
void darkenNight(
  mlr::vtkinputs::Trajectory& trajectory, const double* up, std::vector<std::string>& warnings)
{
  const mlr::Vec3 zenith(up[0], up[1], up[2]);
  std::vector<std::size_t> darkened, disagree;
  std::vector<mlr::PoseInput>& sun = trajectory.lights.front();
  for (std::size_t f = 0; f < sun.size(); ++f)
  {
    const bool below = sunBelowHorizon(trajectory, f, zenith);
    if (below != (mlr::dot(sun[f].position, zenith) < 0))
    {
      disagree.push_back(f);
    }
    if (below)
    {
      if (sun[f].power != mlr::Rgb())
      {
        darkened.push_back(f);
      }
      sun[f].power = mlr::Rgb();
    }
  }
  const std::string upText =
    mlr::formatNumber(up[0]) + ", " + mlr::formatNumber(up[1]) + ", " + mlr::formatNumber(up[2]);
  if (!darkened.empty())
  {
    warnings.push_back("the sun is below the horizon (up " + upText + ") in " +
      std::to_string(darkened.size()) + " of " + mlr::countOf(sun.size(), "frame") + ", " +
      framesNamed(darkened) + ": " + (darkened.size() == 1 ? "that frame is" : "those frames are") +
      " night, dark");
  }
  if (!disagree.empty())
  {
    warnings.push_back("the Trajectory's SunElevation and the filter's Up (" + upText +
      ") disagree on which side of the horizon the sun is in " + framesNamed(disagree) +
      ": set Up to the Sun Path source's Up (0, 1, 0 for a Y-up scene)");
  }
}

/// Each frame's daylight as a sky sees it: the sun (the zenith without a directional light),
/// its direct normal irradiance, the diffuse horizontal irradiance and the day, from the
/// Trajectory's arrays or else the properties.
std::vector<mlr::SkyFrame> daylightFrames(vtkMovingLightRadiosity* self,
  const mlr::vtkinputs::Trajectory& trajectory, bool directional, const mlr::Vec3& up)
{
  std::vector<mlr::SkyFrame> frames;
  if (directional)
  {
    const std::vector<mlr::PoseInput>& sun = trajectory.lights.front();
    for (std::size_t f = 0; f < sun.size(); ++f)
    {
      mlr::SkyFrame frame;
      frame.sun = mlr::normalize(sun[f].position);
      frame.directNormal = self->GetSunIrradiance() * sun[f].power.r;
      frames.push_back(frame);
    }
  }
  else
  {
    frames.resize(std::max<std::size_t>(1, trajectory.times.size()));
    for (mlr::SkyFrame& frame : frames)
    {
      frame.sun = up;
    }
  }
  for (std::size_t f = 0; f < frames.size(); ++f)
  {
    // SkyDiffuseHorizontal is a daylight sky's: under a sun below the horizon it is night. A
    // frame's own value (a weather file's) is a measurement, twilight included.
    const bool night = directional && sunBelowHorizon(trajectory, f, up);
    frames[f].diffuseHorizontal = f < trajectory.skyDiffuseHorizontal.size()
      ? trajectory.skyDiffuseHorizontal[f]
      : (night ? 0.0 : self->GetSkyDiffuseHorizontal());
    if (f < trajectory.directNormal.size())
    {
      frames[f].directNormal = trajectory.directNormal[f];
    }
    if (f < trajectory.dayOfYear.size())
    {
      frames[f].dayOfYear = trajectory.dayOfYear[f];
    }
  }
  return frames;
}

/// The sky of SkyModel in `rig`: one frame per sun direction of a directional light (or one
/// frame), E_dh and E_dn from the Trajectory's arrays or the properties, and per frame the
/// Perez luminous efficacy of the daylight a horizontal surface receives into `efficacy`.
void addSky(vtkMovingLightRadiosity* self, const mlr::vtkinputs::Trajectory& trajectory,
  bool directional, mlr::LightRig& rig, std::vector<double>& efficacy,
  std::vector<double>& sunEfficacy, std::vector<std::string>& warnings)
{
  static const mlr::SkyModel models[] = { mlr::SkyModel::Uniform, mlr::SkyModel::CieOvercast,
    mlr::SkyModel::CieClear, mlr::SkyModel::Perez };
  const mlr::SkyModel model = models[self->GetSkyModel() - 1];
  const double* u = self->GetUp();
  const mlr::Vec3 up(u[0], u[1], u[2]);
  if (!directional && (model == mlr::SkyModel::CieClear || model == mlr::SkyModel::Perez))
  {
    throw mlr::Error("the " + mlr::skyModelName(model) +
      " sky follows the sun: set LightType to Directional with the sun's directions as the "
      "Trajectory, or choose the uniform or cie-overcast sky");
  }
  const std::vector<mlr::SkyFrame> frames = daylightFrames(self, trajectory, directional, up);
  rig.skies.emplace_back(model, up, frames, self->GetNumberOfThreads());
  const std::vector<std::size_t> uniform = rig.skies.back().uniformInsteadFrames();
  if (!uniform.empty())
  {
    std::ostringstream s;
    s << "the Perez sky is negative everywhere (its fit for a high sun with little diffuse "
         "light) in ";
    if (rig.skies.back().positions() == 1)
    {
      s << "every frame";
    }
    else
    {
      s << framesNamed(uniform);
    }
    s << ": drawn as a uniform sky of the same diffuse irradiance, as Radiance's gendaymtx does";
    warnings.push_back(s.str());
  }
  for (const mlr::SkyFrame& frame : frames)
  {
    const mlr::DaylightEfficacy k = mlr::perezEfficacy(frame, up);
    const double sine = std::max(0.0, mlr::dot(frame.sun, mlr::normalize(up)));
    const double direct =
      directional && self->GetSunIrradiance() > 0 ? frame.directNormal * sine : 0;
    const double total = direct + frame.diffuseHorizontal;
    efficacy.push_back(
      total > 0 ? (k.direct * direct + k.diffuse * frame.diffuseHorizontal) / total : k.diffuse);
    sunEfficacy.push_back(k.direct);
  }
}

/// The Trajectory's positions, else the straight path from PathStart (or from `start`, where
/// the Scene has a LightMaterial's lamp) to PathEnd. `forTimes`: only its times are wanted,
/// so directions of the sun that no solve can use are left for the solve to refuse (a script
/// sets LightType before PathStart and PathEnd, and ParaView asks for the times between).
mlr::vtkinputs::Trajectory trajectoryOf(vtkMovingLightRadiosity* self,
  vtkInformationVector* trajectoryInput, std::size_t lights, const std::optional<mlr::Vec3>& start,
  bool forTimes = false)
{
  if (self->GetNumberOfInputConnections(vtkMovingLightRadiosity::TRAJECTORY_PORT) == 0)
  {
    if (lights > 1)
    {
      throw mlr::Error("the Light holds " + std::to_string(lights) +
        " lights (LightId): "
        "connect a Trajectory with one polyline per light");
    }
    const double* given = self->GetPathStart();
    const mlr::Vec3 first = start ? *start : mlr::Vec3(given[0], given[1], given[2]);
    const double* end = self->GetPathEnd();
    if (self->GetLightType() == vtkMovingLightRadiosity::AREA_LIGHT && !*self->GetLightMaterial() &&
      self->GetNumberOfInputConnections(vtkMovingLightRadiosity::LIGHT_PORT) == 0)
    {
      // No light: the scene's own emissive surfaces light it, and nothing moves: one frame,
      // not NumberOfPositions copies of it.
      return mlr::vtkinputs::straightTrajectory(first, first, 1);
    }
    mlr::vtkinputs::Trajectory line = mlr::vtkinputs::straightTrajectory(
      first, { end[0], end[1], end[2] }, self->GetNumberOfPositions());
    if (self->GetLightType() == vtkMovingLightRadiosity::DIRECTIONAL_LIGHT && !forTimes)
    {
      for (std::size_t k = 0; k < line.lights[0].size(); ++k)
      {
        if (!(mlr::length(line.lights[0][k].position) > 0))
        {
          throw mlr::Error("LightType Directional without a Trajectory takes its directions "
                           "towards the sun from PathStart to PathEnd, and frame " +
            std::to_string(k) +
            "'s is zero or not a number: give PathStart and PathEnd as directions (e.g. 1, 0, 1 "
            "and -1, 0, 1: "
            "the sun from +x to -x at 45 degrees), or connect a Trajectory of directions, as "
            "the Sun Path source gives");
        }
      }
    }
    return line;
  }
  return mlr::vtkinputs::trajectoryFromPoints(vtkPointSet::GetData(trajectoryInput, 0), lights);
}

/// The LightDistributionFile's luminaire, read once per solve; none without a file.
std::optional<mlr::Luminaire> luminaireOf(vtkMovingLightRadiosity* self)
{
  const std::string file = self->GetLightDistributionFile();
  if (file.empty())
  {
    return std::nullopt;
  }
  if (self->GetSpotHalfAngle() > 0)
  {
    // Named before the file is read: the conflict is the thing to fix, whatever the file.
    std::ostringstream message;
    message << "both a LightDistributionFile and a spot (SpotHalfAngle " << self->GetSpotHalfAngle()
            << " degrees) are set: give one of them";
    throw mlr::Error(message.str());
  }
  return mlr::readPhotometricFile(file);
}

/// The distribution every area and point light emits with: the file's, a spot, or
/// Lambertian.
mlr::IntensityDistribution lightDistribution(
  vtkMovingLightRadiosity* self, const std::optional<mlr::Luminaire>& luminaire)
{
  const double half = self->GetSpotHalfAngle(), soft = self->GetSpotSoftEdge();
  std::ostringstream message;
  if (luminaire && half > 0)
  {
    message << "both a LightDistributionFile and a spot (SpotHalfAngle " << half
            << " degrees) are set: give one of them";
    throw mlr::Error(message.str());
  }
  if (luminaire)
  {
    return luminaire->distribution;
  }
  if (half > 0)
  {
    return mlr::IntensityDistribution::spot(half * M_PI / 180, soft * M_PI / 180);
  }
  if (soft > 0)
  {
    message << "SpotSoftEdge is " << soft
            << " degrees but SpotHalfAngle is 0 (no spot): give the spot's half angle too";
    throw mlr::Error(message.str());
  }
  return mlr::IntensityDistribution::lambertian();
}

/// The efficacy of each time step the sensors' metrics count: the daylight's of its frame
/// (`daylight`, `sun`: the direct sun's), or the light's `luminous` where there is none.
void setMetricEfficacies(const std::vector<double>& daylight, const std::vector<double>& sun,
  double luminous, mlr::vtksensors::MetricSteps& steps)
{
  steps.efficacy.clear();
  steps.sunEfficacy.clear();
  for (std::size_t t = 0; t < steps.frame.size(); ++t)
  {
    steps.efficacy.push_back(
      daylight.empty() ? luminous : daylight[std::min(t, daylight.size() - 1)]);
    steps.sunEfficacy.push_back(sun.empty() ? luminous : sun[std::min(t, sun.size() - 1)]);
  }
}

/// A light's power: `colour` itself (W), or with LightFluxLumens (or LightFluxFromFile, the
/// file's own flux) that colour scaled to those lumens / LuminousEfficacy watts of luminance.
mlr::Rgb luminairePower(vtkMovingLightRadiosity* self, const mlr::Rgb& colour,
  const std::optional<mlr::Luminaire>& luminaire)
{
  double lumens = self->GetLightFluxLumens();
  if (!(lumens > 0) && self->GetLightFluxFromFile() && luminaire)
  {
    lumens = luminaire->lumens;
  }
  if (!(lumens > 0))
  {
    return colour;
  }
  const double luminance = mlr::luminance(colour);
  if (!(luminance > 0))
  {
    std::ostringstream message;
    message << "LightFluxLumens needs a light colour (LightPower) with some luminance: it is ("
            << colour.r << ", " << colour.g << ", " << colour.b << ")";
    throw mlr::Error(message.str());
  }
  return colour * (lumens / self->GetLuminousEfficacy() / luminance);
}

/// Warns when area light `index`'s extent along its C0-C180 and C90-C270 axes differs by more
/// than a quarter from the file's luminous opening: the light keeps its polygons, but the
/// file's near field came from the other size (or the light's first edge, which sets C = 0,
/// runs along the file's width).
void compareWithOpening(const mlr::MovingLight& light, std::size_t index,
  const mlr::Luminaire& luminaire, const std::string& file, std::vector<std::string>& warnings)
{
  if (luminaire.opening == mlr::OpeningShape::None)
  {
    return;
  }
  const mlr::PhotometricFrame& frame = light.ownPhotometricFrame();
  double low[2] = { 1e300, 1e300 }, high[2] = { -1e300, -1e300 };
  for (const std::vector<mlr::Vec3>& polygon : light.polygons())
  {
    for (const mlr::Vec3& p : polygon)
    {
      const double along[2] = { mlr::dot(p, frame.x), mlr::dot(p, frame.y) };
      for (int a = 0; a < 2; ++a)
      {
        low[a] = std::min(low[a], along[a]);
        high[a] = std::max(high[a], along[a]);
      }
    }
  }
  const double extent[2] = { high[0] - low[0], high[1] - low[1] };
  const double opening[2] = { luminaire.length, luminaire.width };
  auto differs = [](double a, double b) { return a > 1.25 * b || b > 1.25 * a; };
  if (differs(extent[0], opening[0]) || differs(extent[1], opening[1]))
  {
    std::ostringstream s;
    s.precision(3);
    s << "light " << index << " is " << extent[0] << " m along its C0-C180 axis (its first edge) "
      << "by " << extent[1] << " m across, but " << file << "'s luminous opening (a "
      << luminaire.openingName << ") is " << opening[0] << " by " << opening[1]
      << " m: the light emits from its own polygons; give polygons of the opening's size (or "
      << "LightType Luminaire, which emits from the opening), or turn the polygon's first edge "
      << "to the opening's length";
    warnings.push_back(s.str());
  }
}

/// A triangle facing -z: its mean normal is a point light's nadir before posing, so that
/// Core's pose inputs turn a point light as they turn an area light.
const std::vector<std::vector<mlr::Vec3>> PointLightNadir = { { { 0, 0, 0 }, { 0, 1, 0 },
  { 1, 0, 0 } } };
}

//------------------------------------------------------------------------------
int vtkMovingLightRadiosity::RequestInformation(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // The time steps are the trajectory's points (read per light, so the Light's LightId too),
  // which exist only once they have executed: bring them up to date now rather than declare
  // steps that RequestData would contradict.
  for (int port : { LIGHT_PORT, TRAJECTORY_PORT })
  {
    if (this->GetNumberOfInputConnections(port) > 0)
    {
      int producerPort = 0;
      vtkAlgorithm* producer = this->GetInputAlgorithm(port, 0, producerPort);
      if (mlr::vtkparallel::controller())
      {
        // Whole on every rank, so that every rank declares the same time steps (a reader
        // gives ranks other than 0 nothing when asked for their piece).
        vtkNew<vtkInformationVector> requests;
        requests->SetNumberOfInformationObjects(producer->GetNumberOfOutputPorts());
        vtkInformation* whole = requests->GetInformationObject(producerPort);
        whole->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), 0);
        whole->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), 1);
        whole->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
        producer->Update(producerPort, requests);
      }
      else
      {
        producer->Update(producerPort);
      }
    }
  }
  std::vector<double> times;
  try
  {
    // Where the straight path starts does not change its times.
    times = trajectoryOf(this, inputVector[TRAJECTORY_PORT],
      lightsOf(this, inputVector[LIGHT_PORT]), std::nullopt, true)
              .times;
  }
  catch (const mlr::Error& e)
  {
    vtkErrorMacro(<< e.what());
    // No RequestData follows: empty the outputs here rather than leave an earlier result.
    this->Internals->Clear();
    for (int port = 0; port < this->GetNumberOfOutputPorts(); ++port)
    {
      vtkPolyData::GetData(outputVector, port)->Initialize();
    }
    return 0;
  }

  const double range[2] = { times.front(), times.back() };
  for (int port = 0; port < this->GetNumberOfOutputPorts(); ++port)
  {
    vtkInformation* outInfo = outputVector->GetInformationObject(port);
    if (mlr::vtkparallel::controller())
    {
      // Every rank must execute, whatever piece it asks for: the ranks solve together.
      outInfo->Set(vtkAlgorithm::CAN_HANDLE_PIECE_REQUEST(), 1);
    }
    outInfo->Set(
      vtkStreamingDemandDrivenPipeline::TIME_STEPS(), times.data(), static_cast<int>(times.size()));
    outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
  }
  return 1;
}

//------------------------------------------------------------------------------
int vtkMovingLightRadiosity::RequestUpdateExtent(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!this->Superclass::RequestUpdateExtent(request, inputVector, outputVector))
  {
    return 0;
  }
  // The executive asks for the update extent before every execution, and before its progress
  // of 0: an abort silences the update it stopped, not the next one.
  this->ProgressStopped = false;
  // Our time is the light's position, not the inputs' time: a new time must not make the
  // scene, the light or the trajectory execute again. An input with time steps of its own (a
  // file series) is asked for its first: left to whatever time another consumer of the same
  // output last asked for (ParaView's view of the reader), the scene solved would follow the
  // time bar, one step late.
  for (int port = 0; port < this->GetNumberOfInputPorts(); ++port)
  {
    for (int i = 0; i < inputVector[port]->GetNumberOfInformationObjects(); ++i)
    {
      vtkInformation* input = inputVector[port]->GetInformationObject(i);
      const auto steps = vtkStreamingDemandDrivenPipeline::TIME_STEPS();
      if (input->Length(steps) > 0)
      {
        input->Set(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP(), input->Get(steps)[0]);
      }
      else
      {
        input->Remove(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
      }
    }
  }
  return 1;
}

//------------------------------------------------------------------------------
int vtkMovingLightRadiosity::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  for (int port = 0; port < this->GetNumberOfOutputPorts(); ++port)
  {
    vtkPolyData::GetData(outputVector, port)->Initialize();
  }
  const std::string outOfRange = propertyOutOfRange(this);
  if (!outOfRange.empty())
  {
    vtkErrorMacro(<< outOfRange);
    return 0;
  }
  vtkInternals& cache = *this->Internals;
  // Whether anything that decides the result changed since the last solve or attempt: a
  // property, or anything upstream (an algorithm, or data given with SetInputData). Not the
  // inputs' own modification times: an input shared with another consumer executes again for
  // that consumer's time steps, the same content at our fixed time.
  bool unchanged = this->GetMTime() <= cache.PropertiesTime.GetMTime();
  for (int port = 0; unchanged && port < this->GetNumberOfInputPorts(); ++port)
  {
    if (this->GetNumberOfInputConnections(port) == 0)
    {
      continue;
    }
    auto* upstream = vtkDemandDrivenPipeline::SafeDownCast(this->GetInputExecutive(port, 0));
    vtkDataObject* input = vtkDataObject::GetData(inputVector[port], 0);
    const vtkMTimeType changed = upstream ? upstream->GetPipelineMTime()
      : input                             ? input->GetMTime()
                                          : 0;
    unchanged = changed <= cache.SolveTime.GetMTime();
  }
  if (unchanged && cache.Failed)
  {
    // The executive runs the filter again for another time step, another port or piece:
    // requests that need not reach every rank (a script may update one rank alone), so no
    // solve may start here, as a solve waits for every rank. Properties and inputs change
    // on every rank alike, and only their change solves again.
    if (cache.Aborted)
    {
      this->ProgressStopped = true;
      vtkErrorMacro(<< "the last solve was aborted and nothing has changed since: change a "
                       "property or an input, or call Modified() (on every rank), to solve "
                       "again");
    }
    else
    {
      vtkErrorMacro(<< cache.Failure);
    }
    return 0;
  }
  // The time step asked for: with CachedChunks, the first solve keeps its chunk.
  const int fromPort = request->Has(vtkExecutive::FROM_OUTPUT_PORT())
    ? std::max(request->Get(vtkExecutive::FROM_OUTPUT_PORT()), 0)
    : 0;
  vtkInformation* trigger = outputVector->GetInformationObject(fromPort);
  const bool timed = trigger->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
  this->RequestedTime =
    timed ? trigger->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()) : std::nan("");
  if (!(unchanged && cache.HasResult) && !this->Solve(inputVector))
  {
    return 0;
  }

  // All the outputs show the frame asked for on the port whose update runs this request, so that
  // UpdateTimeStep(t) followed by GetOutput(PATCHES_PORT) gives the patches of time t too.
  const double requested = timed ? this->RequestedTime : cache.Times.front();
  const std::size_t frame = mlr::vtkinputs::frameAtOrBelow(cache.Times, requested);
  for (int port = 0; port < this->GetNumberOfOutputPorts(); ++port)
  {
    vtkPolyData* output = vtkPolyData::GetData(outputVector, port);
    if (!this->FillOutput(port, frame, output))
    {
      return 0;
    }
  }
  return 1;
}

//------------------------------------------------------------------------------
bool vtkMovingLightRadiosity::FillOutput(int port, std::size_t frame, vtkPolyData* output)
{
  vtkInternals& cache = *this->Internals;
  auto efficacyOf = [this](const vtkInternals& c, std::size_t f)
  {
    return c.DaylightEfficacy.empty()
      ? this->LuminousEfficacy
      : c.DaylightEfficacy[std::min(f, c.DaylightEfficacy.size() - 1)];
  };
  // A scene lit only by things that do not move (its emitters, static lights) is solved once,
  // whatever time steps the Trajectory or NumberOfPositions declare: every step shows it.
  // The frames of this time step: in the Solution, or in a block of this rank's. Streamed
  // chunks leave only the last chunk's frames, from FirstFrame on.
  const mlr::Solution* frames = &cache.Solution;
  std::size_t solved = 0;
  bool held = true;
  if (!cache.RankFrames.empty())
  {
    held = false;
    // Nothing moves: the one frame solved serves every time step. (A rank may also hold frame
    // 0 alone of an animation whose other frames other ranks hold.)
    const bool oneFrame = mlr::frameCount(cache.Rig, true) == 1;
    for (mlr::vtkparallel::FrameBlock& block : cache.RankFrames)
    {
      const std::size_t n = block.frames.frameCount();
      if ((oneFrame && block.first == 0) || (frame >= block.first && frame < block.first + n))
      {
        frames = &block.frames;
        solved = n == 1 ? 0 : frame - block.first;
        held = true;
        break;
      }
    }
  }
  else if (cache.Solution.frameCount() > 1 &&
    (frame < cache.FirstFrame || frame >= cache.FirstFrame + cache.Solution.frameCount()) &&
    cache.FramesApart)
  {
    held = false; // streamed by the rank that solved it, or by this rank before its last chunk
  }
  else if (cache.Solution.frameCount() > 1 &&
    (frame < cache.FirstFrame || frame >= cache.FirstFrame + cache.Solution.frameCount()))
  {
    vtkErrorMacro(<< "time step " << frame << " was streamed to the chunk observer and is no "
                  << "longer kept (frames " << cache.FirstFrame << " to "
                  << cache.FirstFrame + cache.Solution.frameCount() - 1
                  << " are): solve again without the observer to keep every frame");
    return false;
  }
  else
  {
    solved = cache.Solution.frameCount() > 1 ? frame - cache.FirstFrame : 0;
  }
  if (!held && cache.ChunkScene && (port == ELEMENTS_PORT || port == PATCHES_PORT))
  {
    // A chunk the cache dropped: solved again, with the chunk before it for its seam.
    const mlr::ChunkPlan plan =
      mlr::planChunks(cache.Times.size(), cache.FramesPerChunk, cache.ChunkOptions.chunkOverlap);
    std::size_t chunk = 0;
    while (chunk + 1 < plan.chunks.size() && frame >= plan.finishedEnd(chunk))
    {
      ++chunk;
    }
    try
    {
      cache.cacheChunk(plan.finishedBegin(chunk),
        mlr::solveChunk(*cache.ChunkScene, cache.Rig, cache.ChunkOptions, cache.FramesPerChunk,
          chunk, cache.FirstChunkLitSides, cache.FirstChunkPatchLitSides, cache.ChunkBatches,
          [this](double fraction)
          {
            this->UpdateProgress(fraction);
            return !this->CheckAbort();
          }),
        static_cast<std::size_t>(this->CachedChunks));
    }
    catch (const mlr::Cancelled&)
    {
      this->ProgressStopped = true;
      vtkErrorMacro(<< "aborted while solving chunk " << chunk + 1 << " again for time step "
                    << frame);
      return false;
    }
    catch (const std::exception& e)
    {
      vtkErrorMacro(<< "solving chunk " << chunk + 1 << " again for time step " << frame
                    << " failed: " << e.what());
      return false;
    }
    ++cache.ChunksSolvedAgain;
    frames = &cache.RankFrames.front().frames;
    solved = frame - cache.RankFrames.front().first;
    held = true;
  }
  else if (held && cache.ChunkScene && frames != &cache.RankFrames.front().frames)
  {
    // A hit moves its chunk first, so that the cache drops the chunk asked for longest ago.
    auto hit = std::find_if(cache.RankFrames.begin(), cache.RankFrames.end(),
      [&](const mlr::vtkparallel::FrameBlock& b) { return &b.frames == frames; });
    std::rotate(cache.RankFrames.begin(), hit, hit + 1);
    frames = &cache.RankFrames.front().frames;
  }
  // Frames apart: the rank that holds this time step outputs all of it, the others nothing.
  const bool cut = cache.Distributed && !cache.FramesApart;
  if (cache.Elements)
  {
    if ((port == ELEMENTS_PORT || port == PATCHES_PORT) && !held)
    {
      output->Initialize();
    }
    else if (port == ELEMENTS_PORT)
    {
      output->ShallowCopy(cache.Elements);
      mlr::vtkoutputs::addElementRadiosity(*frames, solved, cache.TwoSided, output->GetCellData());
      mlr::vtkoutputs::addDisplayArrays(*frames, cache.Shading, solved,
        std::exp2(cache.AutoExposure + this->Exposure), output->GetPointData(),
        output->GetCellData());
      mlr::vtkoutputs::addIrradianceArrays(*frames, cache.Shading, solved, efficacyOf(cache, frame),
        cache.TwoSided, output->GetPointData(), output->GetCellData());
      mlr::vtkoutputs::addStdErrorArrays(*frames, cache.Shading, solved, efficacyOf(cache, frame),
        cache.TwoSided, output->GetPointData(), output->GetCellData());
      if (cut)
      {
        // Cut from the whole frame, so that the point arrays at the cut average over the
        // cells of both sides, as in serial.
        output->ShallowCopy(mlr::vtkparallel::extractCells(output, cache.OwnedElements));
      }
    }
    else if (port == PATCHES_PORT)
    {
      output->ShallowCopy(cache.Patches);
      mlr::vtkoutputs::addPatchRadiosity(
        *frames, cache.PatchLitSides, solved, output->GetCellData());
      if (cut)
      {
        output->ShallowCopy(mlr::vtkparallel::extractCells(output, cache.OwnedPatches));
      }
    }
    else if (port == SENSORS_OUTPUT_PORT)
    {
      if (cache.SensorMesh && cache.OutputsLight)
      {
        if (cache.SensorSteps.autonomyThreshold != this->DaylightAutonomyThreshold ||
          cache.SensorEfficacy != this->LuminousEfficacy)
        {
          cache.SensorSteps.autonomyThreshold = this->DaylightAutonomyThreshold;
          setMetricEfficacies(
            cache.DaylightEfficacy, cache.SunEfficacy, this->LuminousEfficacy, cache.SensorSteps);
          cache.SensorEfficacy = this->LuminousEfficacy;
          cache.SensorMesh =
            mlr::vtksensors::sensorMesh(cache.SensorPoints, cache.Sensors, cache.SensorSteps);
        }
        output->ShallowCopy(cache.SensorMesh);
        mlr::vtksensors::addSensorArrays(
          cache.Sensors, solved, efficacyOf(cache, frame), output->GetPointData());
      }
    }
    else if (cache.OutputsLight)
    {
      // Every area and point light as solved: posed as in this frame, at this frame's power
      // (its Trajectory Power and TILT factors included) and that power's flux.
      vtkNew<vtkAppendPolyData> lights;
      for (const mlr::MovingLight& light : cache.Rig.areaLights)
      {
        const std::size_t k = light.frameCount() > 1 ? frame : 0;
        mlr::vtkoutputs::LightTransform transform;
        transform.rotation = light.pose(k).rotation.rows();
        transform.translation = light.rigidTranslation(k);
        lights->AddInputData(
          mlr::vtkoutputs::posedLight(light.polygons(), transform, emittedPower(light, frame)));
      }
      for (const mlr::PointLight& light : cache.Rig.pointLights)
      {
        const std::size_t k = light.frameCount() > 1 ? frame : 0;
        lights->AddInputData(
          mlr::vtkoutputs::posedPointLight(light.position(k), emittedPower(light, frame)));
      }
      if (lights->GetNumberOfInputConnections(0) > 0)
      {
        lights->Update();
        output->ShallowCopy(lights->GetOutput());
        mlr::vtkoutputs::addLuminousFlux(output, this->LuminousEfficacy);
      }
    }
    vtkNew<vtkFieldData> fieldData;
    fieldData->ShallowCopy(cache.Statistics);
    // The first area light's place; a directional light's direction.
    mlr::Vec3 position, translation;
    if (!cache.Rig.areaLights.empty())
    {
      const mlr::MovingLight& light = cache.Rig.areaLights.front();
      const std::size_t k = light.frameCount() > 1 ? frame : 0;
      position = light.pose(k).position;
      translation = light.translation(k);
    }
    else if (!cache.Rig.pointLights.empty())
    {
      const mlr::PointLight& light = cache.Rig.pointLights.front();
      position = light.position(light.frameCount() > 1 ? frame : 0);
      translation = position - light.position(0);
    }
    mlr::vtkoutputs::addFrameFieldData(fieldData, frame, position, translation, this->SolveCount);
    if (!cache.Rig.areaLights.empty() || !cache.Rig.pointLights.empty())
    {
      // What the lights emit in this frame, in all: the Light output's Power summed, so that
      // a series says which frames a dimmed or switched light was solved at.
      mlr::Rgb power;
      for (const mlr::MovingLight& light : cache.Rig.areaLights)
      {
        power += emittedPower(light, frame);
      }
      for (const mlr::PointLight& light : cache.Rig.pointLights)
      {
        power += emittedPower(light, frame);
      }
      vtkNew<vtkDoubleArray> total;
      total->SetName("LightPower");
      total->SetNumberOfComponents(3);
      total->InsertNextTuple3(power.r, power.g, power.b);
      fieldData->AddArray(total);
      mlr::vtkoutputs::addValue<vtkDoubleArray>(
        fieldData, "LightLuminousFlux", this->LuminousEfficacy * mlr::luminance(power));
    }
    if (cache.ChunkScene)
    {
      mlr::vtkoutputs::addValue<vtkIntArray>(
        fieldData, "ChunksSolvedAgain", cache.ChunksSolvedAgain);
    }
    if (!cache.Rig.directionalLights.empty())
    {
      const mlr::DirectionalLight& sun = cache.Rig.directionalLights.front();
      const mlr::Vec3& s = sun.direction(sun.frameCount() > 1 ? frame : 0);
      vtkNew<vtkDoubleArray> direction;
      direction->SetName("SunDirection");
      direction->SetNumberOfComponents(3);
      direction->InsertNextTuple3(s.x, s.y, s.z);
      fieldData->AddArray(direction);
      for (const auto& [name, values] : { std::make_pair("SunAzimuth", &cache.SunAzimuth),
             std::make_pair("SunElevation", &cache.SunElevation) })
      {
        if (frame < values->size())
        {
          vtkNew<vtkDoubleArray> angle;
          angle->SetName(name);
          angle->InsertNextValue((*values)[frame]);
          fieldData->AddArray(angle);
        }
      }
    }
    mlr::vtkoutputs::addExposureFieldData(fieldData, cache.AutoExposure, this->Exposure);
    mlr::vtkoutputs::addValue<vtkDoubleArray>(
      fieldData, "LuminousEfficacy", efficacyOf(cache, frame));
    if (!cache.DaylightEfficacy.empty())
    {
      vtkNew<vtkStringArray> model;
      model->SetName("LuminousEfficacyModel");
      model->InsertNextValue(this->SkyModel != NO_SKY
          ? "Perez (1990) direct and diffuse efficacies, weighted by the frame's direct and "
            "diffuse horizontal irradiance"
          : "Perez (1990) efficacy of the direct sun");
      fieldData->AddArray(model);
    }
    // The meshes' own field data: the scene's MaterialNames beside a MaterialId passed on.
    vtkPolyData* mesh = port == ELEMENTS_PORT ? cache.Elements.Get()
      : port == PATCHES_PORT                  ? cache.Patches.Get()
                                              : nullptr;
    for (int a = 0; mesh && a < mesh->GetFieldData()->GetNumberOfArrays(); ++a)
    {
      fieldData->AddArray(mesh->GetFieldData()->GetAbstractArray(a));
    }
    output->SetFieldData(fieldData);
  }
  output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), cache.Times[frame]);
  return true;
}

//------------------------------------------------------------------------------
void vtkMovingLightRadiosity::SetChunkObserver(ChunkObserver observer)
{
  // Like SetAbortExecute, no MTime: the observer decides where frames go, not what they are.
  this->ChunkFramesObserver = std::move(observer);
}

//------------------------------------------------------------------------------
bool vtkMovingLightRadiosity::Solve(vtkInformationVector** inputVector)
{
  vtkInternals& cache = *this->Internals;
  cache.Clear();
  cache.SolveTime.Modified();
  cache.PropertiesTime.Modified();

  // Several ranks (pvbatch --symmetric, pvserver under mpiexec) agree twice: once their
  // inputs are read (A) and once the solve's outputs are built (B); Core agrees in between.
  // A rank that fails anywhere still joins the next agreement, so no rank waits forever and
  // every rank reports the error.
  vtkMultiProcessController* controller = mlr::vtkparallel::controller();
  enum class Stage
  {
    Reading,
    Solving,
    Agreed
  };
  Stage stage = Stage::Reading;
  vtkInformationVector* inputs[4] = { inputVector[0], inputVector[1], inputVector[2],
    inputVector[3] };
  vtkNew<vtkInformationVector> gathered[4];
  vtkSmartPointer<vtkDataObject> wholeInputs[4];
  std::vector<int> cellRanks;
  double secondsGatheringInputs = 0;
  std::string failure;
  bool cancelled = false, elsewhere = false;
  std::vector<std::string> warnings;
  vtkNew<vtkInformationVector> surfaces[2];
  try
  {
    // An input that is a time series is taken at its first step (RequestUpdateExtent): a
    // Trajectory of one point per step is no path, so say so.
    const char* portNames[4] = { "Scene", "Light", "Trajectory", "Sensors" };
    for (int port = 0; port < 4; ++port)
    {
      vtkInformation* info = inputVector[port]->GetInformationObject(0);
      const int steps = info ? info->Length(vtkStreamingDemandDrivenPipeline::TIME_STEPS()) : 0;
      if (steps > 1)
      {
        std::ostringstream message;
        message << "the " << portNames[port] << " input has " << steps
                << " time steps: only its first (time "
                << info->Get(vtkStreamingDemandDrivenPipeline::TIME_STEPS())[0]
                << ") is used; give one data set"
                << (port == TRAJECTORY_PORT ? " whose points are the light's positions" : "");
        warnings.push_back(message.str());
      }
    }
    // The Scene and the Light as polygons, whatever data they are, before their pieces travel
    // between ranks. A Scene block without a material array takes the default material.
    const std::vector<std::pair<std::string, double>> sceneMaterialFills = {
      { this->ReflectanceArrayName, mlr::Material().reflectance.g },
      { this->EmissionArrayName, 0.0 }
    };
    const std::vector<std::pair<std::string, double>> noFills;
    for (const int port : { SCENE_PORT, LIGHT_PORT })
    {
      if (inputVector[port]->GetNumberOfInformationObjects() > 0)
      {
        vtkNew<vtkInformation> info;
        info->Set(vtkDataObject::DATA_OBJECT(),
          mlr::vtkinputs::surfaceOf(vtkDataObject::GetData(inputVector[port], 0),
            port == SCENE_PORT ? "Scene" : "Light", warnings,
            port == SCENE_PORT ? sceneMaterialFills : noFills));
        surfaces[port]->Append(info);
        inputs[port] = surfaces[port];
      }
    }
    if (controller)
    {
      // The solve's first collective would wait in silence for a rank that never comes.
      mlr::vtkparallel::rendezvous(
        controller, mlr::vtkparallel::rankWaitLimit(),
        [this](const std::string& message) { vtkWarningMacro(<< message); },
        [this](const std::string& message) { vtkErrorMacro(<< message); });
      // Every rank gets the whole Scene, Light and Trajectory, whatever pieces arrived.
      const auto start = std::chrono::steady_clock::now();
      for (int port = 0; port < 4; ++port)
      {
        if (inputVector[port]->GetNumberOfInformationObjects() == 0)
        {
          continue; // an optional input not connected, on every rank alike
        }
        wholeInputs[port] =
          mlr::vtkparallel::gatherPieces(controller, vtkDataObject::GetData(inputs[port], 0),
            portNames[port], port == SCENE_PORT ? &cellRanks : nullptr);
        vtkNew<vtkInformation> info;
        info->Set(vtkDataObject::DATA_OBJECT(), wholeInputs[port]);
        gathered[port]->Append(info);
        inputs[port] = gathered[port];
      }
      secondsGatheringInputs =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    vtkPolyData* lightData = vtkPolyData::GetData(inputs[LIGHT_PORT], 0);
    const bool directional = this->LightType == DIRECTIONAL_LIGHT;
    if (this->SkyModel != NO_SKY && !directional &&
      (this->LightType != AREA_LIGHT || !this->LightMaterial.empty() ||
        (lightData && lightData->GetNumberOfCells() > 0)))
    {
      // A frame's Illuminance takes one efficacy, the daylight's: a lamp's lux would be
      // wrong, so the lamp is refused rather than solved in daylight's lumens or left out.
      throw mlr::Error("a sky lights the scene alone or with the sun (LightType Directional), "
                       "not with a lamp: the Light, LightMaterial or point light would be left "
                       "out. Solve the lamp and the sky apart (their Irradiance arrays add up), "
                       "or set SkyModel to none");
    }
    vtkPolyData* sceneData = vtkPolyData::GetData(inputs[SCENE_PORT], 0);
    const bool fromMaterial = this->LightType == AREA_LIGHT && !this->LightMaterial.empty();
    mlr::vtkinputs::MaterialLight materialLight;
    std::optional<mlr::Vec3> lampInScene;
    if (fromMaterial)
    {
      materialLight =
        mlr::vtkinputs::materialLight(sceneData, this->LightMaterial, this->EmissionArrayName);
      if (this->PathFromLightMaterial)
      {
        // The centroid the light's poses are taken about, so that the first frame moves the
        // lamp by exactly nothing.
        lampInScene = mlr::MovingLight(
          materialLight.light.polygons, mlr::Rgb(1, 1, 1), std::vector<mlr::Vec3>{ mlr::Vec3() })
                        .centroid();
      }
    }
    mlr::vtkinputs::Trajectory trajectory =
      trajectoryOf(this, inputs[TRAJECTORY_PORT], lightsOf(this, inputs[LIGHT_PORT]), lampInScene);
    if (directional)
    {
      darkenNight(trajectory, this->Up, warnings);
    }
    const mlr::PolygonSoup soup = mlr::vtkinputs::sceneSoup(sceneData, warnings,
      static_cast<std::uint64_t>(this->MemoryLimit) << 20, this->ReflectanceArrayName,
      this->EmissionArrayName, materialLight.materialId);
    // glTF is Y-up; Up's default is Z-up. Where Up sets the sky or a TILT table, say so.
    auto* format = vtkStringArray::SafeDownCast(
      sceneData ? sceneData->GetFieldData()->GetAbstractArray("SceneFormat") : nullptr);
    if (format && format->GetNumberOfValues() > 0 && format->GetValue(0) == "glTF" &&
      (this->SkyModel != NO_SKY || !this->LightDistributionFile.empty()) && this->Up[0] == 0 &&
      this->Up[1] == 0 && this->Up[2] > 0)
    {
      warnings.push_back("the Scene was read from glTF, which is Y-up, but Up is +z: for a "
                         "Y-up scene set Up to 0, 1, 0 (and on a Sun Path source Up 0, 1, 0 "
                         "and North 0, 0, -1)");
    }
    const bool turned = this->AimAtPoint ||
      std::any_of(trajectory.lights.begin(), trajectory.lights.end(),
        [](const std::vector<mlr::PoseInput>& poses)
        {
          return std::any_of(poses.begin(), poses.end(),
            [](const mlr::PoseInput& p) { return p.hasNormal || p.hasOrientation; });
        });
    if (format && format->GetNumberOfValues() > 0 && format->GetValue(0) == "glTF" && !turned &&
      (this->LightType == POINT_LIGHT || this->LightType == LUMINAIRE_LIGHT))
    {
      // A point light or luminaire faces -z as given: down in a Z-up scene only.
      warnings.push_back("the Scene was read from glTF, which is Y-up, and the " +
        std::string(this->LightType == POINT_LIGHT ? "point light" : "luminaire") +
        " faces -z, sideways in it: turn it down with AimAtPoint (--aim), or a Trajectory "
        "Normal 0, -1, 0");
    }
    cache.Times = trajectory.times;
    cache.WantedFrame = std::isnan(this->RequestedTime)
      ? 0
      : mlr::vtkinputs::frameAtOrBelow(cache.Times, this->RequestedTime);
    // A weather file's frames may skip hours (one per day at noon), a sun path's not: its
    // source says how long a frame lasts.
    vtkDataObject* path = vtkDataObject::GetData(inputs[TRAJECTORY_PORT], 0);
    vtkDataArray* step = path ? path->GetFieldData()->GetArray("TimeStepHours") : nullptr;
    cache.HoursPerStep = step && step->GetNumberOfTuples() > 0 &&
        std::isfinite(step->GetComponent(0, 0)) && step->GetComponent(0, 0) > 0
      ? step->GetComponent(0, 0)
      : mlr::hoursPerTimeStep(cache.Times);
    cache.SunAzimuth = trajectory.sunAzimuth;
    cache.SunElevation = trajectory.sunElevation;
    if (soup.polygons.empty() && fromMaterial && !materialLight.light.polygons.empty())
    {
      throw mlr::Error("LightMaterial '" + this->LightMaterial +
        "' takes every polygon of the Scene: nothing is left to light; give the Scene "
        "surfaces of other materials, or choose another LightMaterial");
    }
    if (soup.polygons.empty())
    {
      if (!sceneData || sceneData->GetNumberOfCells() == 0)
      {
        // Connected, so meant to be lit: empty outputs alone would not say why.
        warnings.push_back("the Scene input is connected but empty (no cells; an upstream "
                           "filter gave nothing?): the outputs are empty");
      }
      for (const std::string& warning : warnings)
      {
        vtkWarningMacro(<< warning);
      }
      cache.HasResult = true; // nothing to light: empty outputs, which is no error
      return true;
    }

    // The lights and the options are checked before remeshing, which may take a while.
    mlr::LightRig rig;
    // The photometric file is read once: its distribution, flux, TILT table and opening.
    const std::optional<mlr::Luminaire> luminaire =
      this->SkyModel != NO_SKY ? std::nullopt : luminaireOf(this);
    if (luminaire)
    {
      warnings.insert(warnings.end(), luminaire->warnings.begin(), luminaire->warnings.end());
    }
    const mlr::Vec3 up(this->Up[0], this->Up[1], this->Up[2]);
    if (directional)
    {
      std::vector<mlr::Vec3> directions;
      std::vector<mlr::Rgb> factors;
      for (const mlr::PoseInput& in : trajectory.lights.front())
      {
        directions.push_back(in.position);
        factors.push_back(in.power);
      }
      // A weather file's sun: its direct normal irradiance per frame, not SunIrradiance.
      const bool perFrame = !trajectory.directNormal.empty();
      for (std::size_t f = 0; perFrame && f < factors.size(); ++f)
      {
        factors[f] =
          factors[f] * trajectory.directNormal[std::min(f, trajectory.directNormal.size() - 1)];
      }
      // 0 is no direct sun; anything else (NaN too) is the DirectionalLight's to check.
      if (!(this->SunIrradiance == 0))
      {
        rig.directionalLights.emplace_back(
          directions, mlr::Rgb(perFrame ? 1.0 : this->SunIrradiance), factors);
      }
      else
      {
        // No direct sun, but its frames: every position off.
        rig.directionalLights.emplace_back(
          directions, mlr::Rgb(1.0), std::vector<mlr::Rgb>(directions.size(), mlr::Rgb()));
      }
    }
    cache.DaylightEfficacy.clear();
    cache.SunEfficacy.clear();
    if (this->SkyModel != NO_SKY)
    {
      addSky(
        this, trajectory, directional, rig, cache.DaylightEfficacy, cache.SunEfficacy, warnings);
    }
    else if (directional)
    {
      // Direct sunlight is not white light: Perez's efficacy of the direct beam for each
      // frame's sun and weather (about 90 to 105 lm/W for a high clear sun), as with a sky.
      for (const mlr::SkyFrame& frame : daylightFrames(this, trajectory, true, up))
      {
        cache.DaylightEfficacy.push_back(mlr::perezEfficacy(frame, up).direct);
      }
      cache.SunEfficacy = cache.DaylightEfficacy;
    }
    else if (this->LightType == POINT_LIGHT || this->LightType == LUMINAIRE_LIGHT)
    {
      std::vector<mlr::PoseInput> inputs = trajectory.lights.front();
      const mlr::Vec3 aim(this->AimPoint[0], this->AimPoint[1], this->AimPoint[2]);
      if (this->AimAtPoint)
      {
        if (const std::optional<std::size_t> k = mlr::aimAt(inputs, aim))
        {
          throw mlr::Error("the point light is at AimPoint in frame " + std::to_string(*k) +
            " and cannot face it: move AimPoint off the light's Trajectory, or turn AimAtPoint "
            "off");
        }
      }
      const mlr::Rgb power = luminairePower(
        this, mlr::Rgb(this->LightPower[0], this->LightPower[1], this->LightPower[2]), luminaire);
      const mlr::IntensityDistribution distribution = lightDistribution(this, luminaire);
      bool fromOpening = false;
      if (this->LightType == LUMINAIRE_LIGHT)
      {
        if (!luminaire)
        {
          throw mlr::Error("LightType Luminaire emits from a photometric file's luminous "
                           "opening: give its LightDistributionFile (.ies or .ldt)");
        }
        // Only here does the light emit from the opening, so only here do its limits matter.
        warnings.insert(
          warnings.end(), luminaire->openingWarnings.begin(), luminaire->openingWarnings.end());
        fromOpening = luminaire->opening != mlr::OpeningShape::None;
        if (!fromOpening && luminaire->openingWarnings.empty())
        {
          warnings.push_back(this->LightDistributionFile + " gives no luminous opening (its " +
            luminaire->openingName + "): the luminaire is a point light");
        }
      }
      if (fromOpening)
      {
        const std::vector<std::vector<mlr::Vec3>> opening = { mlr::openingPolygon(*luminaire) };
        rig.areaLights.emplace_back(
          opening, power, mlr::posesFromInputs(opening, inputs, warnings));
        mlr::MovingLight& light = rig.areaLights.back();
        light.setDistribution(distribution);
        if (!luminaire->tilt.empty())
        {
          light.setPoses(mlr::tiltPoses(luminaire->tilt, light.ownPhotometricFrame(), light.poses(),
            up, this->LightDistributionFile, warnings));
        }
      }
      else
      {
        rig.pointLights.emplace_back(
          power, mlr::posesFromInputs(PointLightNadir, inputs, warnings), distribution);
        mlr::PointLight& light = rig.pointLights.back();
        if (luminaire && !luminaire->tilt.empty())
        {
          light.setPoses(mlr::tiltPoses(luminaire->tilt, light.ownPhotometricFrame(), light.poses(),
            up, this->LightDistributionFile, warnings));
        }
      }
    }
    else if (fromMaterial || (lightData && lightData->GetNumberOfCells() > 0))
    {
      std::vector<mlr::vtkinputs::LightInput> lights;
      if (fromMaterial)
      {
        lights.push_back(materialLight.light);
        if (this->LightPowerFromMaterial && !materialLight.light.hasPower &&
          !(this->LightFluxLumens > 0) && !this->LightFluxFromFile)
        {
          warnings.push_back("the LightMaterial '" + this->LightMaterial +
            "' emits nothing of its own (no emission): the light emits LightPower, " +
            mlr::formatNumber(this->LightPower[0]) + ", " + mlr::formatNumber(this->LightPower[1]) +
            ", " + mlr::formatNumber(this->LightPower[2]) + " W");
        }
        lights.back().hasPower = lights.back().hasPower && this->LightPowerFromMaterial;
      }
      else
      {
        lights = mlr::vtkinputs::lightInputs(lightData);
      }
      const mlr::Rgb defaultPower(this->LightPower[0], this->LightPower[1], this->LightPower[2]);
      const mlr::Vec3 aim(this->AimPoint[0], this->AimPoint[1], this->AimPoint[2]);
      for (std::size_t i = 0; i < lights.size(); ++i)
      {
        std::vector<mlr::PoseInput> inputs = trajectory.lights[i];
        if (this->AimAtPoint)
        {
          // Core would blame a zero Normal, which the user never gave: name AimPoint.
          if (const std::optional<std::size_t> k = mlr::aimAt(inputs, aim))
          {
            throw mlr::Error("light " + std::to_string(i) +
              " (in LightId order) is at "
              "AimPoint in frame " +
              std::to_string(*k) +
              " and cannot face it: move "
              "AimPoint off the light's Trajectory, or turn AimAtPoint off");
          }
        }
        const std::vector<mlr::LightPose> poses =
          mlr::posesFromInputs(lights[i].polygons, inputs, warnings);
        rig.areaLights.emplace_back(lights[i].polygons,
          luminairePower(this, lights[i].hasPower ? lights[i].power : defaultPower, luminaire),
          poses);
      }
      const mlr::IntensityDistribution distribution = lightDistribution(this, luminaire);
      for (std::size_t i = 0; i < rig.areaLights.size(); ++i)
      {
        mlr::MovingLight& light = rig.areaLights[i];
        light.setDistribution(distribution);
        if (luminaire)
        {
          compareWithOpening(light, i, *luminaire, this->LightDistributionFile, warnings);
          if (!luminaire->tilt.empty())
          {
            light.setPoses(mlr::tiltPoses(luminaire->tilt, light.ownPhotometricFrame(),
              light.poses(), up, this->LightDistributionFile, warnings));
          }
        }
      }
    }
    else if (lightData)
    {
      // Connected, so meant to light: say so before "nothing emits light" would follow.
      warnings.push_back("the Light input is connected but empty (no cells; an upstream filter "
                         "gave nothing?): it lights nothing");
    }
    // Inputs and properties that would change nothing: the user meant something by them.
    if (lightData && lightData->GetNumberOfCells() > 0 &&
      (directional || this->LightType == POINT_LIGHT || fromMaterial))
    {
      warnings.push_back(std::string("the Light input is not used: ") +
        (directional                         ? "LightType Directional is the sun"
            : this->LightType == POINT_LIGHT ? "LightType Point emits from the Trajectory's points"
                                             : "the LightMaterial's surfaces are the light") +
        "; disconnect it, or choose LightType Area for its polygons");
    }
    if (rig.areaLights.empty() && rig.pointLights.empty() && rig.directionalLights.empty() &&
      rig.skies.empty() && this->GetNumberOfInputConnections(TRAJECTORY_PORT) > 0)
    {
      warnings.push_back("the Trajectory moves no light: without a Light or a LightMaterial the "
                         "Scene's own emissive surfaces light it, and they stay where they are "
                         "in every time step");
    }
    if (this->TimeLimit > 0 && !(this->TargetRelativeError > 0))
    {
      warnings.push_back("TimeLimit stops the rounds of a TargetRelativeError, and there is "
                         "none: the solve runs its NumberOfPaths whatever the time");
    }
    // The Scene's own arrays, which every element and patch will carry.
    const std::vector<vtkAbstractArray*> passedArrays =
      mlr::vtkoutputs::sceneCellArraysToPass(sceneData, &warnings);
    for (const std::string& warning : warnings)
    {
      vtkWarningMacro(<< warning);
    }

    mlr::AnimationOptions options;
    mlr::SolverOptions& solverOptions = options.solver;
    solverOptions.pathsPerFrame = static_cast<std::uint64_t>(this->NumberOfPaths);
    solverOptions.gatheringRatio = this->GatheringRatio;
    solverOptions.firstBounceSurvival = this->FirstBounceSurvival;
    solverOptions.reuseShooting = this->ReuseShooting != 0;
    solverOptions.balanceFrames = this->BalanceFrames != 0;
    solverOptions.reuseGathering = this->ReuseGathering != 0;
    solverOptions.twoSided = this->TwoSided != 0;
    solverOptions.seed = static_cast<std::uint64_t>(this->Seed);
    solverOptions.threads = this->NumberOfThreads;
    solverOptions.memoryLimitBytes = static_cast<std::uint64_t>(this->MemoryLimit) << 20;
    solverOptions.framesPerChunk = static_cast<std::uint64_t>(this->FramesPerChunk);
    solverOptions.chunkOverlap = static_cast<std::uint64_t>(this->ChunkOverlap);
    // Core refuses the other bad values (NaN targets included) naming the property to fix.
    solverOptions.errorBatches = static_cast<std::uint64_t>(this->ErrorBatches);
    solverOptions.targetRelativeError = this->TargetRelativeError;
    solverOptions.timeLimitSeconds = this->TimeLimit;
    options.remeshing.targetEdgeLength = this->PatchSize;
    // The outputs' estimate is linear in the counts; per item, rounded up.
    constexpr std::size_t many = std::size_t(1) << 20;
    options.outputBytesPerElement =
      (mlr::vtkoutputs::estimateOutputMemory(many, 0) + many - 1) / many +
      (mlr::vtkoutputs::bytesPerCell(passedArrays) * 5 + 3) / 4;
    options.outputBytesPerPoint =
      (mlr::vtkoutputs::estimateOutputMemory(0, many) + many - 1) / many;
    mlr::validateOptions(solverOptions);
    options.sensors =
      mlr::vtksensors::sensorsFromPoints(vtkPointSet::GetData(inputs[SENSORS_PORT], 0));
    options.sensorOptions.hemisphereRays = static_cast<std::uint32_t>(this->SensorRays);
    options.sensorOptions.areaLightSamples =
      std::max<std::uint32_t>(1, options.sensorOptions.hemisphereRays / SensorRaysPerLightSample);
    if (controller)
    {
      // The ranks must solve the same thing: they compare a digest of the solve's settings
      // and gathered inputs, so that a rank that re-executed alone fails them all rather
      // than adding up two different solves.
      mlr::vtkparallel::Digest digest;
      digest.add(mlr::digestOf(solverOptions));
      digest.add(options.remeshing.targetEdgeLength);
      digest.add(static_cast<std::uint64_t>(soup.points.size()));
      digest.add(static_cast<std::uint64_t>(soup.polygons.size()));
      digest.add(static_cast<std::uint64_t>(
        rig.areaLights.size() + rig.pointLights.size() + rig.directionalLights.size()));
      digest.add(static_cast<std::uint64_t>(trajectory.times.size()));
      digest.add(static_cast<std::uint64_t>(options.sensors.size()));
      digest.add(static_cast<std::uint64_t>(this->SensorRays));
      const mlr::vtkparallel::Verdict verdict =
        mlr::vtkparallel::agree(controller, false, false, {}, digest.value);
      stage = verdict.failed ? Stage::Agreed : Stage::Solving;
      if (verdict.failed)
      {
        throw mlr::Error(verdict.message);
      }
      mlr::vtkparallel::shareSolve(controller, solverOptions);
    }
    const bool reportsProgress = !controller || controller->GetLocalProcessId() == 0;

    this->SetProgressText(nullptr);
    if (reportsProgress)
    {
      // The error estimate's rounds and estimates: the progress text ParaView shows, and the
      // debug output.
      solverOptions.log = [this](const std::string& message)
      {
        this->SetProgressText(message.c_str());
        // An event of its own (Core logs on this thread): a chunk's last round and the next
        // chunk's first line come before any progress, and an observer saw only the second.
        this->UpdateProgress(this->GetProgress());
        vtkDebugMacro(<< message);
      };
    }
    // Streaming: each chunk's frames go to the observer once final, and are freed after. A
    // solve in one chunk comes whole, and is kept as without the observer.
    std::optional<mlr::Solution> whole;
    bool streamed = false;
    std::optional<double> firstChunkExposure;
    // Several ranks keep the frames as they come, chunk by chunk: each rank those of the
    // chunks it solved when there are at least as many chunks as ranks (Core's ranks then
    // take whole chunks), so that a long animation's frames are shared out, not repeated.
    const bool keepsRankFrames =
      controller && !this->ChunkFramesObserver && options.sensors.empty();
    std::vector<mlr::vtkparallel::FrameBlock> rankFrames;
    // CachedChunks: the frames come chunk by chunk, and the last chunks stay.
    const bool cachesChunks = this->CachedChunks > 0 && !this->ChunkFramesObserver && !controller &&
      options.sensors.empty();
    StreamedErrors streamedErrors;
    double secondsStreaming = 0;
    if (keepsRankFrames)
    {
      options.keptStreamedChunks = std::numeric_limits<std::size_t>::max();
      options.chunkFrames = [&](const mlr::Animation&, std::size_t first, mlr::Solution& frames) {
        rankFrames.push_back({ first, std::move(frames) });
      };
    }
    else if ((this->ChunkFramesObserver || cachesChunks) && options.sensors.empty())
    {
      // The display's exposure is the first chunk's on every rank (over ranks that take
      // whole chunks, rank 0 solved it), so that every chunk's frames look alike.
      options.firstChunkFigure.compute = [](const mlr::Solution& frames)
      { return mlr::vtkoutputs::autoExposure(frames); };
      options.firstChunkFigure.receive = [&](double exposure) { firstChunkExposure = exposure; };
      if (cachesChunks)
      {
        options.keptStreamedChunks = static_cast<std::size_t>(this->CachedChunks);
      }
      options.chunkFrames =
        [&](const mlr::Animation& solving, std::size_t first, mlr::Solution& frames)
      {
        // Every solved frame at once (one chunk, or lights that do not move). Not a first
        // chunk's single finished frame, which chunks of 2 hand on before their seam.
        if (first == 0 && frames.frameCount() == mlr::frameCount(rig, true))
        {
          whole = std::move(frames);
          return;
        }
        if (!streamed)
        {
          // The display of every frame, from the first chunk: its lit sides are every chunk's.
          cache.Rig = rig;
          cache.Shading = mlr::vtkoutputs::smoothShading(solving.scene, frames);
          cache.Elements = mlr::vtkoutputs::smoothElementMesh(solving.scene, cache.Shading);
          cache.AutoExposure =
            firstChunkExposure ? *firstChunkExposure : mlr::vtkoutputs::autoExposure(frames);
          cache.Patches = mlr::vtkoutputs::patchMesh(solving.scene, solving.patches.points.size());
          mlr::vtkoutputs::passSceneCellArrays(
            sceneData, passedArrays, solving.scene, cache.Elements, cache.Patches);
          cache.PatchLitSides = mlr::vtkoutputs::patchLitSides(frames);
          cache.TwoSided = solverOptions.twoSided;
          cache.FirstChunkLitSides = frames.litSideData();
          cache.FirstChunkPatchLitSides = frames.patchLitSideData();
          streamed = true;
        }
        // The frames carry the statistics of their chunk; the last update, the animation's.
        cache.Statistics = mlr::vtkoutputs::statisticsFieldData(frames.statistics, solverOptions);
        // Every frame's error figures, for the field data of every time step after the solve
        // (the command line's error line and --stats read the last one's).
        streamedErrors.add(first, frames.errorEstimate);
        if (cachesChunks)
        {
          cache.cacheChunk(first, std::move(frames), static_cast<std::size_t>(this->CachedChunks));
          return;
        }
        cache.Solution = std::move(frames);
        cache.FirstFrame = first;
        // Timed: handing frames on happens inside the solve, and a caller that writes them
        // would otherwise count its writing as solving.
        const auto handing = std::chrono::steady_clock::now();
        for (std::size_t f = first; f < first + cache.Solution.frameCount(); ++f)
        {
          if (this->CheckAbort())
          {
            break;
          }
          vtkNew<vtkPolyData> elements;
          if (this->FillOutput(ELEMENTS_PORT, f, elements))
          {
            this->ChunkFramesObserver(f, elements);
          }
        }
        secondsStreaming +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - handing).count();
      };
    }
    // Remeshing's warnings as soon as the scene is built, so that a run refused by its memory
    // limit, cancelled or stopped during the solve still shows them.
    options.sceneWarning = [this](const std::string& warning) { vtkWarningMacro(<< warning); };
    mlr::Animation animation = mlr::solveAnimation(soup, rig, options,
      [this, reportsProgress](double fraction)
      {
        // Core reports progress on this thread, so the abort flag can be polled right here.
        // Rank 0 reports for all: the ranks advance together.
        if (reportsProgress)
        {
          this->UpdateProgress(fraction);
        }
        return !this->CheckAbort();
      });
    for (const std::string& warning : animation.warnings)
    {
      vtkWarningMacro(<< warning);
    }
    const mlr::Scene& scene = animation.scene;
    if (whole)
    {
      whole->statistics = animation.solution.statistics;
      animation.solution = std::move(*whole);
    }
    mlr::Solution& solution = animation.solution;
    std::optional<mlr::vtkparallel::RankFramesDisplay> apart;
    if (keepsRankFrames)
    {
      apart = mlr::vtkparallel::combineRankFrames(scene, rankFrames,
        static_cast<std::size_t>(solution.statistics.frames), solution, solverOptions);
      solution = std::move(apart->summary);
    }
    if (streamed)
    {
      this->CheckAbort();
      if (this->GetAbortExecute())
      {
        throw mlr::Cancelled();
      }
      // The frames went to the observer, or to the cache of chunks; the last chunk's stay,
      // with the whole solve's statistics.
      cache.Statistics = mlr::vtkoutputs::statisticsFieldData(solution.statistics, solverOptions);
      if (this->ChunkFramesObserver)
      {
        mlr::vtkoutputs::addValue<vtkDoubleArray>(
          cache.Statistics, "SecondsStreaming", secondsStreaming);
      }
      if (!controller)
      {
        streamedErrors.addTo(cache.Statistics, solution.errorEstimate,
          static_cast<std::size_t>(solution.statistics.frames), nullptr);
      }
    }
    else
    {
      cache.Rig = std::move(rig);
      cache.Shading = mlr::vtkoutputs::smoothShading(scene, solution);
      cache.Elements = mlr::vtkoutputs::smoothElementMesh(scene, cache.Shading);
      cache.AutoExposure = apart ? apart->exposure : mlr::vtkoutputs::autoExposure(solution);
      cache.Patches = mlr::vtkoutputs::patchMesh(scene, animation.patches.points.size());
      mlr::vtkoutputs::passSceneCellArrays(
        sceneData, passedArrays, scene, cache.Elements, cache.Patches);
      cache.Statistics = mlr::vtkoutputs::statisticsFieldData(solution.statistics, solverOptions);
      mlr::vtkoutputs::addErrorFieldData(cache.Statistics, solution);
      cache.PatchLitSides = mlr::vtkoutputs::patchLitSides(solution);
    }
    if (!options.sensors.empty())
    {
      // The metrics count every time step, each showing its solved frame (one for a scene
      // lit by static lights), with the efficacy its Illuminance takes.
      mlr::vtksensors::MetricSteps steps;
      steps.hoursPerStep = cache.HoursPerStep;
      steps.autonomyThreshold = this->DaylightAutonomyThreshold;
      for (std::size_t t = 0; t < cache.Times.size(); ++t)
      {
        steps.frame.push_back(solution.frameCount() > 1 ? t : 0);
      }
      setMetricEfficacies(cache.DaylightEfficacy, cache.SunEfficacy, this->LuminousEfficacy, steps);
      cache.SensorEfficacy = this->LuminousEfficacy;
      cache.Sensors = std::move(animation.sensors);
      mlr::vtksensors::addSensorStatistics(cache.Statistics, cache.Sensors);
      cache.SensorMesh = mlr::vtksensors::sensorMesh(options.sensors, cache.Sensors, steps);
      cache.SensorPoints = std::move(options.sensors);
      cache.SensorSteps = std::move(steps);
    }
    if (!streamed)
    {
      cache.Solution = std::move(solution);
      cache.TwoSided = solverOptions.twoSided;
    }
    if (apart)
    {
      cache.RankFrames = std::move(rankFrames);
      cache.FramesApart = apart->apart;
    }
    else if (streamed && controller)
    {
      cache.FramesApart = true; // each rank streamed the chunks it solved
    }
    if (controller)
    {
      const int rank = controller->GetLocalProcessId();
      vtkPolyData* wholeScene = vtkPolyData::SafeDownCast(wholeInputs[SCENE_PORT]);
      const std::vector<int> elementOwners =
        mlr::vtkparallel::owners(wholeScene, cellRanks, scene.points(), scene.elementTriangles());
      const std::vector<int> patchOwners =
        mlr::vtkparallel::owners(wholeScene, cellRanks, scene.points(), scene.patchTriangles());
      for (std::size_t e = 0; e < elementOwners.size(); ++e)
      {
        if (elementOwners[e] == rank)
        {
          cache.OwnedElements.push_back(static_cast<vtkIdType>(e));
        }
      }
      for (std::size_t p = 0; p < patchOwners.size(); ++p)
      {
        if (patchOwners[p] == rank)
        {
          cache.OwnedPatches.push_back(static_cast<vtkIdType>(p));
        }
      }
      cache.Distributed = cache.OwnedElements.size() != elementOwners.size() ||
        cache.OwnedPatches.size() != patchOwners.size();
      cache.OutputsLight = rank == 0;
      for (const auto& [name, value] :
        { std::make_pair("Ranks", static_cast<double>(controller->GetNumberOfProcesses())),
          std::make_pair("SecondsGatheringInputs", secondsGatheringInputs),
          std::make_pair("SecondsReducing", cache.Solution.statistics.secondsReducing) })
      {
        vtkNew<vtkDoubleArray> array;
        array->SetName(name);
        array->InsertNextValue(value);
        cache.Statistics->AddArray(array);
      }
      const mlr::vtkparallel::Verdict verdict =
        mlr::vtkparallel::agree(controller, false, false, {});
      stage = Stage::Agreed;
      if (verdict.failed)
      {
        throw mlr::Error(verdict.message);
      }
      if (streamed)
      {
        // Every rank is here (agreed): each frame's figures from the rank that holds it.
        streamedErrors.addTo(cache.Statistics, solution.errorEstimate,
          static_cast<std::size_t>(solution.statistics.frames),
          solverOptions.sumDoublesAcrossRanks);
      }
    }
    if (cachesChunks && streamed)
    {
      cache.ChunkScene = std::make_shared<const mlr::Scene>(std::move(animation.scene));
      cache.ChunkOptions = solverOptions;
      cache.ChunkOptions.log = {};
      cache.FramesPerChunk = static_cast<std::size_t>(solution.statistics.framesPerChunk);
      cache.ChunkBatches = solution.errorEstimate.chunkBatches;
    }
    cache.HasResult = true;
    cache.WantedFrame = std::numeric_limits<std::size_t>::max();
    // A statistic, not a property: it must not change the MTime and invalidate the cache.
    ++this->SolveCount;
    return true;
  }
  catch (const mlr::Cancelled& e)
  {
    failure = std::string("aborted: ") + e.what();
    cancelled = true;
  }
  catch (const mlr::FailedOnAnotherRank& e)
  {
    // The rank that failed has the message to report: the agreement below brings it here.
    failure = e.what();
    elsewhere = true;
  }
  catch (const mlr::Error& e)
  {
    failure = e.what();
  }
  catch (const std::bad_alloc&)
  {
    failure = "out of memory: use fewer light positions, a larger PatchSize or a lower "
              "MemoryLimit so that the solve is refused before it starts";
  }
  catch (const std::exception& e)
  {
    failure = std::string("the solve failed: ") + e.what();
  }
  bool aborted = cancelled;
  if (controller && stage != Stage::Agreed)
  {
    const mlr::vtkparallel::Verdict verdict =
      mlr::vtkparallel::agree(controller, !cancelled && !elsewhere, cancelled, failure);
    if (elsewhere && verdict.failed)
    {
      failure = verdict.message;
    }
    // A rank that failed while another was aborted knows it from the verdict only: every
    // rank must keep the same state, or their next requests would differ.
    aborted = verdict.cancelled;
  }
  vtkErrorMacro(<< failure);
  cache.Clear();
  cache.Failed = true;
  cache.Aborted = aborted;
  cache.Failure = failure;
  // The abort is spent on every rank alike: AbortExecute is cleared directly (no MTime
  // change), as this VTK's executive no longer does, and no output is marked ABORTED, which
  // would make the executive run the filter again at the next request of any port on the
  // rank whose CheckAbort fired, alone. SetAbortOutput moves the MTime: the attempt's
  // PropertiesTime follows it, unless a property had changed during the attempt.
  const bool propertiesAsAttempted = this->GetMTime() <= cache.PropertiesTime.GetMTime();
  if (aborted)
  {
    this->AbortExecute = 0;
    this->ProgressStopped = true;
  }
  this->SetAbortOutput(false);
  if (propertiesAsAttempted)
  {
    cache.PropertiesTime.Modified();
  }
  return false;
}

//------------------------------------------------------------------------------
void vtkMovingLightRadiosity::SetAbortExecute(vtkTypeBool abort)
{
  this->AbortExecute = abort;
}

//------------------------------------------------------------------------------
void vtkMovingLightRadiosity::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "LightPower: (" << this->LightPower[0] << ", " << this->LightPower[1] << ", "
     << this->LightPower[2] << ")\n";
  os << indent << "NumberOfPaths: " << this->NumberOfPaths << "\n";
  os << indent << "GatheringRatio: " << this->GatheringRatio << "\n";
  os << indent << "FirstBounceSurvival: " << this->FirstBounceSurvival << "\n";
  os << indent << "ReuseShooting: " << (this->ReuseShooting ? "On" : "Off") << "\n";
  os << indent << "BalanceFrames: " << (this->BalanceFrames ? "On" : "Off") << "\n";
  os << indent << "ReuseGathering: " << (this->ReuseGathering ? "On" : "Off") << "\n";
  os << indent << "PatchSize: " << this->PatchSize << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "TwoSided: " << (this->TwoSided ? "On" : "Off") << "\n";
  os << indent << "PathStart: (" << this->PathStart[0] << ", " << this->PathStart[1] << ", "
     << this->PathStart[2] << ")\n";
  os << indent << "PathEnd: (" << this->PathEnd[0] << ", " << this->PathEnd[1] << ", "
     << this->PathEnd[2] << ")\n";
  os << indent << "NumberOfPositions: " << this->NumberOfPositions << "\n";
  os << indent << "MemoryLimit: " << this->MemoryLimit << " MiB\n";
  os << indent << "FramesPerChunk: " << this->FramesPerChunk << "\n";
  os << indent << "ChunkOverlap: " << this->ChunkOverlap << "\n";
  os << indent << "CachedChunks: " << this->CachedChunks << "\n";
  os << indent << "ErrorBatches: " << this->ErrorBatches << "\n";
  os << indent << "TargetRelativeError: " << this->TargetRelativeError << "\n";
  os << indent << "TimeLimit: " << this->TimeLimit << " s\n";
  static const char* const lightTypes[] = { "Area", "Directional", "Point", "Luminaire" };
  os << indent << "LightType: " << this->LightType;
  if (this->LightType >= AREA_LIGHT && this->LightType <= LUMINAIRE_LIGHT)
  {
    os << " (" << lightTypes[this->LightType] << ")";
  }
  os << "\n";
  os << indent << "SunIrradiance: " << this->SunIrradiance << " W/m^2\n";
  os << indent << "SkyModel: " << this->SkyModel << "\n";
  os << indent << "SkyDiffuseHorizontal: " << this->SkyDiffuseHorizontal << " W/m^2\n";
  os << indent << "Up: " << this->Up[0] << ", " << this->Up[1] << ", " << this->Up[2] << "\n";
  os << indent << "AimAtPoint: " << (this->AimAtPoint ? "On" : "Off") << "\n";
  os << indent << "AimPoint: (" << this->AimPoint[0] << ", " << this->AimPoint[1] << ", "
     << this->AimPoint[2] << ")\n";
  os << indent << "ReflectanceArrayName: " << this->ReflectanceArrayName << "\n";
  os << indent << "EmissionArrayName: " << this->EmissionArrayName << "\n";
  os << indent << "LightMaterial: " << this->LightMaterial << "\n";
  os << indent << "LightDistributionFile: " << this->LightDistributionFile << "\n";
  os << indent << "SpotHalfAngle: " << this->SpotHalfAngle << " degrees\n";
  os << indent << "SpotSoftEdge: " << this->SpotSoftEdge << " degrees\n";
  os << indent << "LightFluxLumens: " << this->LightFluxLumens << " lm\n";
  os << indent << "LightFluxFromFile: " << (this->LightFluxFromFile ? "On" : "Off") << "\n";
  os << indent << "LightPowerFromMaterial: " << (this->LightPowerFromMaterial ? "On" : "Off")
     << "\n";
  os << indent << "PathFromLightMaterial: " << (this->PathFromLightMaterial ? "On" : "Off") << "\n";
  os << indent << "SolveCount: " << this->SolveCount << "\n";
  os << indent << "Exposure: " << this->Exposure << " EV\n";
  os << indent << "LuminousEfficacy: " << this->LuminousEfficacy << " lm/W\n";
  os << indent << "DaylightAutonomyThreshold: " << this->DaylightAutonomyThreshold << " lx\n";
  os << indent << "SensorRays: " << this->SensorRays << "\n";
  os << indent
     << "Cached frames: " << (this->Internals->HasResult ? this->Internals->Times.size() : 0)
     << "\n";
  os << indent << "Progress reports: " << (this->ProgressStopped ? "stopped by an abort" : "on")
     << "\n";
  os << indent << "Last attempt: "
     << (this->Internals->Aborted     ? "aborted"
            : this->Internals->Failed ? "failed: " + this->Internals->Failure
                                      : std::string("none failed"))
     << "\n";
}
