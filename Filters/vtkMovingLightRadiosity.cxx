#include "vtkMovingLightRadiosity.h"

#include "MovingLightRadiosityInputs.h"
#include "MovingLightRadiosityOutputs.h"

#include "Error.h"
#include "MovingLight.h"
#include "Remeshing.h"
#include "Scene.h"
#include "Solver.h"

#include "vtkCellData.h"
#include "vtkDataObject.h"
#include "vtkExecutive.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointSet.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkTimeStamp.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <new>
#include <string>
#include <vector>

static_assert(mlr::MaximumPathsPerFrame == 100000000000ULL,
  "keep the clamp of vtkMovingLightRadiosity::NumberOfPaths equal to Core's maximum");

namespace
{
/// Share of the progress bar given to remeshing; the solve takes the rest.
constexpr double RemeshingShare = 0.05;

std::uint64_t saturatingSum(std::uint64_t a, std::uint64_t b)
{
  return a > UINT64_MAX - b ? UINT64_MAX : a + b;
}
}

/// The last solve: every frame of the animation, kept until an input or a property changes.
struct vtkMovingLightRadiosity::vtkInternals
{
  bool HasResult = false;
  /// Taken just before the inputs and properties were read for the solve.
  vtkTimeStamp SolveTime;
  std::vector<double> Times;
  std::vector<mlr::Vec3> LightPositions;
  mlr::Vec3 LightCentroid;
  // Display (issue 17): the light as given, for the Light output, and what the colours of
  // every frame need.
  std::vector<std::vector<mlr::Vec3>> LightPolygons;
  mlr::Rgb LightPower;
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
  std::vector<mlr::Side> PatchLitSides;
  bool TwoSided = true;

  void Clear()
  {
    const bool aborted = this->Aborted;
    *this = vtkInternals();
    this->Aborted = aborted;
  }

  /// The last solve stopped because AbortExecute was set (it stays set: see RequestData).
  bool Aborted = false;
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
  this->SolveCount = 0;
  this->Exposure = 0.0;

  this->SetNumberOfInputPorts(3);
  this->SetNumberOfOutputPorts(3);
}

//------------------------------------------------------------------------------
vtkMovingLightRadiosity::~vtkMovingLightRadiosity() = default;

//------------------------------------------------------------------------------
void vtkMovingLightRadiosity::SetExposure(double exposure)
{
  exposure = std::clamp(exposure, -20.0, 20.0);
  if (exposure == this->Exposure)
  {
    return;
  }
  // The outputs must be built again, but from the cached solve: when the properties matched
  // the solve before this change, they still do after it.
  vtkInternals& cache = *this->Internals;
  const bool current = cache.HasResult && this->GetMTime() <= cache.PropertiesTime.GetMTime();
  this->Exposure = exposure;
  this->Modified();
  if (current)
  {
    cache.PropertiesTime.Modified();
  }
}

//------------------------------------------------------------------------------
int vtkMovingLightRadiosity::FillInputPortInformation(int port, vtkInformation* info)
{
  if (port == TRAJECTORY_PORT)
  {
    info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
    info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
    return 1;
  }
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  return 1;
}

namespace
{
mlr::vtkinputs::Trajectory trajectoryOf(
  vtkMovingLightRadiosity* self, vtkInformationVector* trajectoryInput)
{
  if (self->GetNumberOfInputConnections(vtkMovingLightRadiosity::TRAJECTORY_PORT) == 0)
  {
    const double* start = self->GetPathStart();
    const double* end = self->GetPathEnd();
    return mlr::vtkinputs::straightTrajectory({ start[0], start[1], start[2] },
      { end[0], end[1], end[2] }, self->GetNumberOfPositions());
  }
  return mlr::vtkinputs::trajectoryFromPoints(vtkPointSet::GetData(trajectoryInput, 0));
}
}

//------------------------------------------------------------------------------
int vtkMovingLightRadiosity::RequestInformation(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (this->GetNumberOfInputConnections(TRAJECTORY_PORT) > 0)
  {
    // The time steps are the trajectory's points, which exist only once it has executed:
    // bring it up to date now rather than declare steps that RequestData would contradict.
    int producerPort = 0;
    vtkAlgorithm* producer = this->GetInputAlgorithm(TRAJECTORY_PORT, 0, producerPort);
    producer->Update(producerPort);
  }
  std::vector<double> times;
  try
  {
    times = trajectoryOf(this, inputVector[TRAJECTORY_PORT]).times;
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
    outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_STEPS(), times.data(),
      static_cast<int>(times.size()));
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
  // Our time is the light's position, not the inputs' time: a new time must not make the
  // scene, the light or the trajectory execute again.
  for (int port = 0; port < this->GetNumberOfInputPorts(); ++port)
  {
    for (int i = 0; i < inputVector[port]->GetNumberOfInformationObjects(); ++i)
    {
      inputVector[port]->GetInformationObject(i)->Remove(
        vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
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
  vtkInternals& cache = *this->Internals;
  if (cache.Aborted)
  {
    // This VTK no longer clears AbortExecute when an execution starts: the flag that stopped
    // the previous solve must not stop this one. Cleared directly, as the executive used to,
    // so that the MTime (and with it the cache key) does not change.
    this->AbortExecute = 0;
    cache.Aborted = false;
  }
  bool current = cache.HasResult && this->GetMTime() <= cache.PropertiesTime.GetMTime();
  for (int port = 0; current && port < this->GetNumberOfInputPorts(); ++port)
  {
    vtkDataObject* input = vtkDataObject::GetData(inputVector[port], 0);
    current = !input || input->GetMTime() <= cache.SolveTime.GetMTime();
  }
  if (!current && !this->Solve(inputVector))
  {
    return 0;
  }

  // All the outputs show the frame asked for on the port whose update runs this request, so that
  // UpdateTimeStep(t) followed by GetOutput(PATCHES_PORT) gives the patches of time t too.
  const int fromPort = request->Has(vtkExecutive::FROM_OUTPUT_PORT())
    ? std::max(request->Get(vtkExecutive::FROM_OUTPUT_PORT()), 0)
    : 0;
  vtkInformation* trigger = outputVector->GetInformationObject(fromPort);
  const double requested = trigger->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
    ? trigger->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP())
    : cache.Times.front();
  const std::size_t frame = mlr::vtkinputs::frameAtOrBelow(cache.Times, requested);

  for (int port = 0; port < this->GetNumberOfOutputPorts(); ++port)
  {
    vtkPolyData* output = vtkPolyData::GetData(outputVector, port);
    if (cache.Elements)
    {
      const mlr::Vec3& position = cache.LightPositions[frame];
      if (port == ELEMENTS_PORT)
      {
        output->ShallowCopy(cache.Elements);
        mlr::vtkoutputs::addElementRadiosity(
          cache.Solution, frame, cache.TwoSided, output->GetCellData());
        mlr::vtkoutputs::addDisplayArrays(cache.Solution, cache.Shading, frame,
          std::exp2(cache.AutoExposure + this->Exposure), output->GetPointData(),
          output->GetCellData());
      }
      else if (port == PATCHES_PORT)
      {
        output->ShallowCopy(cache.Patches);
        mlr::vtkoutputs::addPatchRadiosity(
          cache.Solution, cache.PatchLitSides, frame, output->GetCellData());
      }
      else
      {
        // The light only translates for now: identity rotation.
        mlr::vtkoutputs::LightTransform transform;
        transform.translation = position - cache.LightCentroid;
        output->ShallowCopy(
          mlr::vtkoutputs::posedLight(cache.LightPolygons, transform, cache.LightPower));
      }
      vtkNew<vtkFieldData> fieldData;
      fieldData->ShallowCopy(cache.Statistics);
      mlr::vtkoutputs::addFrameFieldData(
        fieldData, frame, position, position - cache.LightCentroid, this->SolveCount);
      mlr::vtkoutputs::addExposureFieldData(fieldData, cache.AutoExposure, this->Exposure);
      output->SetFieldData(fieldData);
    }
    output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), cache.Times[frame]);
  }
  return 1;
}

//------------------------------------------------------------------------------
bool vtkMovingLightRadiosity::Solve(vtkInformationVector** inputVector)
{
  vtkInternals& cache = *this->Internals;
  cache.Clear();
  cache.SolveTime.Modified();
  cache.PropertiesTime.Modified();

  // Core reports progress on this thread, so the abort flag can be polled right here.
  auto progress = [this](double base, double share) {
    return [this, base, share](double fraction) {
      this->UpdateProgress(base + share * fraction);
      return !this->CheckAbort();
    };
  };

  try
  {
    const mlr::vtkinputs::Trajectory trajectory = trajectoryOf(this, inputVector[TRAJECTORY_PORT]);
    std::vector<std::string> warnings;
    const mlr::PolygonSoup soup = mlr::vtkinputs::sceneSoup(
      vtkPolyData::GetData(inputVector[SCENE_PORT], 0), warnings,
      static_cast<std::uint64_t>(this->MemoryLimit) << 20);
    for (const std::string& warning : warnings)
    {
      vtkWarningMacro(<< warning);
    }
    cache.Times = trajectory.times;
    if (soup.polygons.empty())
    {
      cache.HasResult = true; // nothing to light: empty outputs, which is no error
      return true;
    }

    // The light and the options are checked before remeshing, which may take a while.
    const auto polygons =
      mlr::vtkinputs::lightPolygons(vtkPolyData::GetData(inputVector[LIGHT_PORT], 0));
    const mlr::Rgb power(this->LightPower[0], this->LightPower[1], this->LightPower[2]);
    const mlr::Vec3 centroid = mlr::MovingLight(polygons, power, { mlr::Vec3() }).centroid();
    std::vector<mlr::Vec3> translations;
    for (const mlr::Vec3& position : trajectory.positions)
    {
      translations.push_back(position - centroid);
    }
    const mlr::MovingLight light(polygons, power, translations);
    cache.LightPositions = trajectory.positions;
    cache.LightCentroid = centroid;
    cache.LightPolygons = polygons;
    cache.LightPower = power;

    mlr::SolverOptions options;
    options.pathsPerFrame = static_cast<std::uint64_t>(this->NumberOfPaths);
    options.gatheringRatio = this->GatheringRatio;
    options.firstBounceSurvival = this->FirstBounceSurvival;
    options.reuseShooting = this->ReuseShooting != 0;
    options.reuseGathering = this->ReuseGathering != 0;
    options.twoSided = this->TwoSided != 0;
    options.seed = static_cast<std::uint64_t>(this->Seed);
    options.threads = this->NumberOfThreads;
    options.memoryLimitBytes = static_cast<std::uint64_t>(this->MemoryLimit) << 20;
    mlr::validateOptions(options);

    mlr::RemeshOptions remeshOptions;
    remeshOptions.targetEdgeLength = this->PatchSize;
    remeshOptions.memoryLimitBytes = options.memoryLimitBytes;
    // A solve that cannot fit is refused before remeshing does the work (CGAL may take a
    // while): with the patch count remeshing expects once the polygons are triangulated,
    // halved so that an estimate on the high side never refuses a solve that fits (the exact
    // check follows remeshing).
    remeshOptions.checkExpectedPatches = [&](std::size_t expected) {
      const std::size_t patches = expected / 2;
      mlr::checkSolveMemory(
        saturatingSum(mlr::estimateSolveMemory(
                        patches, 4 * patches, 2 * patches, translations.size(), options),
          mlr::vtkoutputs::estimateOutputMemory(4 * patches, 2 * patches)),
        translations.size(), patches, 4 * patches, options, true);
    };
    const mlr::RemeshResult remeshed =
      mlr::remesh(soup, remeshOptions, progress(0.0, RemeshingShare));
    for (const std::string& warning : remeshed.warnings)
    {
      vtkWarningMacro(<< "Scene: " << warning);
    }
    const mlr::Scene scene = mlr::Scene::fromPatchMesh(remeshed.mesh);
    // The solve checks its own estimate; the outputs built from it come on top.
    mlr::checkSolveMemory(saturatingSum(mlr::estimateSolveMemory(scene, translations.size(), options),
                            mlr::vtkoutputs::estimateOutputMemory(scene.elementCount(), scene.points().size())),
      translations.size(), scene.patchCount(), scene.elementCount(), options);

    mlr::Solution solution =
      mlr::solve(scene, light, options, progress(RemeshingShare, 1.0 - RemeshingShare));
    solution.statistics.secondsRemeshing = remeshed.statistics.seconds;
    for (const std::string& warning : solution.warnings)
    {
      vtkWarningMacro(<< warning);
    }

    cache.Shading = mlr::vtkoutputs::smoothShading(scene, solution);
    cache.Elements = mlr::vtkoutputs::smoothElementMesh(scene, cache.Shading);
    cache.AutoExposure = mlr::vtkoutputs::autoExposure(solution);
    cache.Patches = mlr::vtkoutputs::patchMesh(scene, remeshed.mesh.points.size());
    cache.Statistics = mlr::vtkoutputs::statisticsFieldData(solution.statistics, options);
    cache.PatchLitSides = mlr::vtkoutputs::patchLitSides(solution);
    cache.Solution = std::move(solution);
    cache.TwoSided = options.twoSided;
    cache.HasResult = true;
    // A statistic, not a property: it must not change the MTime and invalidate the cache.
    ++this->SolveCount;
    return true;
  }
  catch (const mlr::Cancelled& e)
  {
    vtkErrorMacro(<< "aborted: " << e.what());
    cache.Clear();
    cache.Aborted = true;
    return false;
  }
  catch (const mlr::Error& e)
  {
    vtkErrorMacro(<< e.what());
  }
  catch (const std::bad_alloc&)
  {
    vtkErrorMacro(<< "out of memory: use fewer light positions, a larger PatchSize or a lower "
                     "MemoryLimit so that the solve is refused before it starts");
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro(<< "the solve failed: " << e.what());
  }
  cache.Clear();
  return false;
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
  os << indent << "SolveCount: " << this->SolveCount << "\n";
  os << indent << "Exposure: " << this->Exposure << " EV\n";
  os << indent << "Cached frames: " << (this->Internals->HasResult ? this->Internals->Times.size() : 0)
     << "\n";
}
