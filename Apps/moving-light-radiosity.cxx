// moving-light-radiosity: solves the animation of a moving light with the VTK filter and
// writes it as a .pvd + .vtu series (and pictures). See helpText() in CommandLine.cxx.
#include "CommandLine.h"
#include "FrameRenderer.h"
#include "InputFiles.h"
#include "Messages.h"
#include "OutputTransaction.h"
#include "ProgressBar.h"
#include "RankJob.h"
#include "Report.h"
#include "Sensors.h"
#include "SeriesWriter.h"

#include "vtkAbstractArray.h"
#include "vtkCallbackCommand.h"
#include "vtkCellData.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkIdList.h"
#include "vtkInformation.h"
#include "vtkInformationDoubleVectorKey.h"
#include "vtkMovingLightRadiosity.h"
#include "vtkNew.h"
#include "vtkOutputWindow.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkSunPathSource.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <optional>
#include <sstream>
#include <thread>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;
using namespace mlr::cli;

namespace
{
constexpr int ExitFailure = 1;
constexpr int ExitUsage = 2;

/// The failure was already reported (by VTK's error output): just exit.
struct AlreadyReported
{
};

/// Under mpiexec, on the ranks that did not fail: the message of the rank that did.
struct FailedOnAnotherRank : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

/// Under mpiexec: this rank owes the others the agreement on its inputs until it has made it,
/// so that a rank that fails before it still meets the others there (main() does).
bool OwesInputAgreement = true;

/// Every rank meets the others here with its `failure` (empty: none); throws it, or
/// FailedOnAnotherRank when another rank failed.
void agreeAcrossRanks(RankJob& job, const std::string& failure = {})
{
  const RankJob::Verdict verdict = job.agree(!failure.empty(), failure);
  if (!failure.empty())
  {
    throw InputError(failure);
  }
  if (verdict.failed)
  {
    throw FailedOnAnotherRank(verdict.message);
  }
}

/// Set by SIGINT/SIGTERM; polled during the solve and between files, so that an interrupted
/// run still removes its temporary files.
std::atomic<bool> Interrupted{ false };

extern "C" void onSignal(int)
{
  Interrupted = true;
}

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Threads that compress and write frames while the main thread converts the next one: one
/// per core beyond the first, up to 3 (beyond that the main thread's frame updates limit).
unsigned writerThreads()
{
  const unsigned cores = std::thread::hardware_concurrency();
  return std::clamp(cores > 1 ? cores - 1 : 1u, 1u, 3u);
}

void throwIfInterrupted()
{
  if (Interrupted)
  {
    throw InputError("interrupted: nothing was written");
  }
}

/// Refuses an output file name that is taken by a directory.
void checkNotADirectory(const fs::path& path, const std::string& what)
{
  std::error_code error;
  if (fs::is_directory(path, error))
  {
    throw InputError(
      "the " + what + " '" + path.string() + "' is a directory: give the name of a file to write");
  }
}

/// Creates `directory` (rolled back with the transaction) and checks that files can be
/// written in it, with a file that is removed again.
void prepareDirectory(OutputTransaction& output, const fs::path& directory)
{
  output.createDirectories(directory);
  const fs::path where = directory.empty() ? fs::path(".") : directory;
  const fs::path probe = where / (".mlr-write-test-" + std::to_string(getpid()));
  {
    std::ofstream file(probe);
    if (!file || !(file << "probe") || !(file.flush()))
    {
      const int code = errno;
      std::error_code error;
      // A directory that exists and refuses new files (/proc, /sys) reports ENOENT.
      const std::string reason = code == ENOENT && fs::is_directory(where, error)
        ? "it accepts no new files (a system directory?): give a directory of your own"
        : std::strerror(code);
      fs::remove(probe, error);
      throw InputError("cannot write in the directory '" + where.string() + "': " + reason);
    }
  }
  std::error_code error;
  fs::remove(probe, error);
}

/// True when `index` is a .pvd collection whose every data set is a file `prefix`NNNN`suffix`
/// beside it: a series the command line wrote, not a file of the user's that happens to bear
/// its name.
bool indexesOnly(const fs::path& index, const std::string& prefix, const std::string& suffix)
{
  std::error_code error;
  const std::uintmax_t size = fs::file_size(index, error);
  if (error || size > (std::uintmax_t(64) << 20))
  {
    return false;
  }
  std::ifstream in(index);
  const std::string text{ std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>() };
  if (text.find("type=\"Collection\"") == std::string::npos)
  {
    return false;
  }
  std::size_t files = 0;
  for (std::size_t at = text.find(" file=\""); at != std::string::npos;
       at = text.find(" file=\"", at + 1))
  {
    const std::size_t begin = at + 7;
    const std::size_t end = text.find('"', begin);
    if (end == std::string::npos || !isSeriesFile(text.substr(begin, end - begin), prefix, suffix))
    {
      return false;
    }
    ++files;
  }
  return files > 0;
}

/// True when the scene's emission array (the filter's EmissionArrayName) has a value above 0.
bool emits(vtkPolyData* scene, const char* arrayName)
{
  vtkDataArray* emission = scene->GetCellData()->GetArray(arrayName);
  if (!emission)
  {
    return false;
  }
  for (int c = 0; c < emission->GetNumberOfComponents(); ++c)
  {
    double range[2];
    emission->GetRange(range, c);
    if (range[1] > 0)
    {
      return true;
    }
  }
  return false;
}

/**
 * Where the lights are, for the work plane to find the floors they light: the trajectory's
 * points (each light's centroid in a frame), the ends and middle of --from/--to, or the
 * centroids of the scene's emitting cells. None under the sun or a sky, which light from
 * above.
 */
std::vector<Triple> lightPositions(const Options& options, vtkPolyData* trajectory,
  vtkPolyData* scene, const char* emissionArrayName)
{
  std::vector<Triple> positions;
  if (options.usesSun() || options.sky)
  {
    return positions;
  }
  if (options.from)
  {
    const Triple& a = *options.from;
    const Triple& b = *options.to;
    positions = { a, { (a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2 }, b };
  }
  else if (trajectory)
  {
    for (vtkIdType i = 0; i < trajectory->GetNumberOfPoints(); ++i)
    {
      double p[3];
      trajectory->GetPoint(i, p);
      positions.push_back({ p[0], p[1], p[2] });
    }
  }
  else if (vtkDataArray* emission = scene->GetCellData()->GetArray(emissionArrayName))
  {
    vtkNew<vtkIdList> ids;
    for (vtkIdType c = 0; c < scene->GetNumberOfCells(); ++c)
    {
      double most = 0;
      for (int k = 0; k < emission->GetNumberOfComponents(); ++k)
      {
        most = std::max(most, emission->GetComponent(c, k));
      }
      scene->GetCellPoints(c, ids);
      if (!(most > 0) || ids->GetNumberOfIds() == 0)
      {
        continue;
      }
      Triple centroid{ 0, 0, 0 };
      for (vtkIdType i = 0; i < ids->GetNumberOfIds(); ++i)
      {
        double p[3];
        scene->GetPoint(ids->GetId(i), p);
        for (int k = 0; k < 3; ++k)
        {
          centroid[k] += p[k] / static_cast<double>(ids->GetNumberOfIds());
        }
      }
      positions.push_back(centroid);
    }
  }
  return positions;
}

std::vector<double> timeSteps(vtkMovingLightRadiosity* filter)
{
  vtkInformation* info = filter->GetOutputInformation(vtkMovingLightRadiosity::ELEMENTS_PORT);
  vtkInformationDoubleVectorKey* key = vtkStreamingDemandDrivenPipeline::TIME_STEPS();
  if (!info->Has(key))
  {
    throw AlreadyReported();
  }
  const double* steps = info->Get(key);
  return std::vector<double>(steps, steps + info->Length(key));
}

/// The frame at `time`, from the filter's cache after the first solve.
vtkPolyData* frameAt(vtkMovingLightRadiosity* filter, double time)
{
  if (!filter->UpdateTimeStep(time))
  {
    throwIfInterrupted(); // the filter's "aborted" error is the interrupt's doing
    throw AlreadyReported();
  }
  return filter->GetOutput(vtkMovingLightRadiosity::ELEMENTS_PORT);
}

void tripleOf(vtkFieldData* data, const char* name, double out[3])
{
  vtkDataArray* array = data->GetArray(name);
  out[0] = out[1] = out[2] = 0;
  if (array && array->GetNumberOfComponents() == 3 && array->GetNumberOfTuples() > 0)
  {
    array->GetTuple(0, out);
  }
}

double valueOf(vtkFieldData* data, const char* name)
{
  vtkDataArray* array = data->GetArray(name);
  return array && array->GetNumberOfTuples() > 0 ? array->GetComponent(0, 0) : 0.0;
}

/// What a frame's field data says of its lights: where the first light is, where the sun is,
/// what the lights emit, and the luminous efficacy of its Illuminance.
void recordLights(FrameRecord& record, vtkFieldData* data)
{
  tripleOf(data, "LightPosition", record.lightPosition.data());
  tripleOf(data, "SunDirection", record.sunDirection.data());
  tripleOf(data, "LightPower", record.lightPower.data());
  record.lightLuminousFlux = valueOf(data, "LightLuminousFlux");
  record.luminousEfficacy = valueOf(data, "LuminousEfficacy");
}

/// Runs the Sun Path source with the scene's north and up; its error, without VTK's location
/// prefix (the source's message ends with what to fix), goes to `fail`, which throws.
vtkSmartPointer<vtkPolyData> updatedSunPath(vtkSunPathSource* source, const Options& options,
  const std::function<void(const std::string& reason)>& fail)
{
  const Triple north = options.northDirection();
  const Triple up = options.zenith();
  source->SetNorth(north.data());
  source->SetUp(up.data());
  std::string error;
  vtkNew<vtkCallbackCommand> onError;
  onError->SetClientData(&error);
  onError->SetCallback([](vtkObject*, unsigned long, void* into, void* message)
    { *static_cast<std::string*>(into) = static_cast<const char*>(message); });
  source->AddObserver(vtkCommand::ErrorEvent, onError);
  source->Update();
  if (!error.empty())
  {
    const std::size_t colon = error.find("): ");
    std::string reason = colon == std::string::npos ? error : error.substr(colon + 3);
    reason.erase(reason.find_last_not_of(" \n") + 1);
    fail(reason);
  }
  vtkSmartPointer<vtkPolyData> path = source->GetOutput();
  return path;
}

/// The sun's directions over the day of --sun-path, with the clock times as Time.
vtkSmartPointer<vtkPolyData> sunPathTrajectory(const Options& options)
{
  const SunPathSpec& spec = *options.sunPath;
  vtkNew<vtkSunPathSource> source;
  source->SetLatitude(spec.latitude);
  source->SetLongitude(spec.longitude);
  source->SetYear(spec.year);
  source->SetMonth(spec.month);
  source->SetDay(spec.day);
  source->SetStartTime(spec.startHour);
  source->SetEndTime(spec.endHour);
  source->SetStepMinutes(spec.stepMinutes);
  source->SetTimeZone(options.timeZone.value_or(0.0));
  return updatedSunPath(
    source, options, [](const std::string& reason) { throw UsageError("--sun-path: " + reason); });
}

/// The hours of --weather as frames: the sun at their middle, Time the hour of the year.
vtkSmartPointer<vtkPolyData> weatherTrajectory(const Options& options)
{
  vtkNew<vtkSunPathSource> source;
  source->SetWeatherFile(options.weather.c_str());
  const std::array<int, 4> dates = options.dates.value_or(std::array<int, 4>{ 1, 1, 12, 31 });
  source->SetFirstDate(dates[0], dates[1]);
  source->SetLastDate(dates[2], dates[3]);
  const std::array<int, 2> hours = options.hours.value_or(std::array<int, 2>{ 0, 23 });
  source->SetHours(hours[0], hours[1]);
  source->SetIncludeNight(options.night);
  // The file's errors are input errors (exit 1), not the command line's.
  return updatedSunPath(
    source, options, [](const std::string& reason) { throw InputError("--weather: " + reason); });
}

/**
 * Under mpiexec, aborts the filter when this process is interrupted. Only rank 0 reports
 * progress, so the other ranks see no progress event to abort from; until they do, rank 0
 * waits for them and mpiexec, which stops a job soon after an interrupt, would kill them
 * before they remove their temporary files.
 */
class InterruptWatcher
{
public:
  explicit InterruptWatcher(vtkMovingLightRadiosity* filter)
    : Thread(
        [this, filter]
        {
          while (!this->Done)
          {
            if (Interrupted)
            {
              abortingTheFilter();
              filter->SetAbortExecuteAndUpdateTime();
              return;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
          }
        })
  {
  }
  ~InterruptWatcher()
  {
    this->Done = true;
    this->Thread.join();
  }

private:
  std::atomic<bool> Done{ false };
  std::thread Thread;
};

/// What `step` threw, as a message; empty when it succeeded.
std::string failureOf(const std::function<void()>& step)
{
  try
  {
    step();
  }
  catch (const AlreadyReported&)
  {
    return lastVtkError().empty() ? "failed" : lastVtkError();
  }
  catch (const std::exception& e)
  {
    return e.what();
  }
  return {};
}

/// Under mpiexec, once every rank has written its frames (`written` of them, or `failure`):
/// the ranks agree, and every frame must have been written exactly once.
void agreeOnFramesWritten(
  RankJob& job, const std::string& failure, long long written, std::size_t frames)
{
  agreeAcrossRanks(job, failure);
  const long long all = job.sum(written);
  if (all != static_cast<long long>(frames))
  {
    throw InputError("the ranks wrote " + std::to_string(all) + " frames of " +
      std::to_string(frames) + ": nothing was written");
  }
}

/**
 * Under mpiexec, after the solve: each frame is written by the rank that holds it. With
 * chunks taken by the ranks a frame is on one rank, its chunk's, and every rank writes its
 * own at once; when every rank holds every frame (the ranks split the paths), the lowest
 * writes them all. Every rank keeps the records of all the frames. A failure or an
 * interrupt stops this rank's writing, and the agreement after it stops every rank's.
 */
std::vector<FrameRecord> writeRankFrames(RankJob& job, vtkMovingLightRadiosity* filter,
  const std::vector<double>& times, const SeriesNaming& naming, OutputTransaction& output)
{
  std::vector<FrameRecord> records;
  std::string failure;
  vtkPolyData* first = nullptr;
  failure = failureOf([&] { first = frameAt(filter, times.front()); });
  const RankJob::Holders holders = job.holders(first && first->GetNumberOfCells() > 0);
  agreeAcrossRanks(job, failure);
  if (holders.count == 0)
  {
    throw InputError("the scene has no polygons or triangle strips to light: nothing to write");
  }
  const bool apart = holders.count == 1;
  const bool writes = apart || holders.lowest == job.rank();
  long long written = 0;
  {
    // Destroyed before the agreement: no frame is still being written when a failure rolls
    // back.
    FrameWriter writer(writerThreads());
    for (std::size_t f = 0; f < times.size() && failure.empty(); ++f)
    {
      failure = failureOf(
        [&]
        {
          throwIfInterrupted();
          FrameRecord record;
          record.time = times[f];
          record.file = naming.frameName(f, ".vtu");
          if (writes)
          {
            vtkPolyData* elements = frameAt(filter, times[f]);
            recordLights(record, elements->GetFieldData());
            if (elements->GetNumberOfCells() > 0)
            {
              writer.write(elements, times[f], output.stage(naming.directory / record.file));
              ++written;
            }
            else if (!apart)
            {
              throw InputError("frame " + std::to_string(f) + " is missing on rank " +
                std::to_string(job.rank()) + ", which holds the others");
            }
          }
          records.push_back(record);
        });
    }
    if (failure.empty())
    {
      failure = failureOf([&] { writer.finish(); });
    }
  }
  agreeOnFramesWritten(job, failure, written, times.size());
  return records;
}

/**
 * Under mpiexec, after a streamed solve: each rank wrote the frames of its chunks as they
 * came (`mine`, of the frames `mineFrames`); the ranks agree that every frame was written once, and
 * every rank gets the records of all, what they say of the lights summed over the ranks.
 */
std::vector<FrameRecord> finishRankStream(RankJob& job, const std::vector<double>& times,
  const SeriesNaming& naming, std::optional<FrameWriter>& writer,
  const std::vector<FrameRecord>& mine, const std::vector<std::size_t>& mineFrames)
{
  std::string failure;
  if (writer)
  {
    failure = failureOf([&] { writer->finish(); });
  }
  agreeOnFramesWritten(job, failure, static_cast<long long>(mine.size()), times.size());
  // Per frame: the light's position, the sun's direction, the luminous efficacy and what the
  // lights emit.
  constexpr std::size_t Values = 11;
  std::vector<double> lights(Values * times.size(), 0.0);
  for (std::size_t i = 0; i < mine.size(); ++i)
  {
    double* at = &lights[Values * mineFrames[i]];
    std::copy(mine[i].lightPosition.begin(), mine[i].lightPosition.end(), at);
    std::copy(mine[i].sunDirection.begin(), mine[i].sunDirection.end(), at + 3);
    at[6] = mine[i].luminousEfficacy;
    std::copy(mine[i].lightPower.begin(), mine[i].lightPower.end(), at + 7);
    at[10] = mine[i].lightLuminousFlux;
  }
  job.sum(lights);
  std::vector<FrameRecord> records(times.size());
  for (std::size_t f = 0; f < times.size(); ++f)
  {
    records[f].time = times[f];
    records[f].file = naming.frameName(f, ".vtu");
    const double* at = &lights[Values * f];
    std::copy(at, at + 3, records[f].lightPosition.begin());
    std::copy(at + 3, at + 6, records[f].sunDirection.begin());
    records[f].luminousEfficacy = at[6];
    std::copy(at + 7, at + 10, records[f].lightPower.begin());
    records[f].lightLuminousFlux = at[10];
  }
  return records;
}

int run(int argc, char** argv, RankJob& job)
{
  const Clock::time_point started = Clock::now();
  const Options options = parseCommandLine(argc, argv);
  if (options.help)
  {
    std::cout << helpText();
    OwesInputAgreement = false; // every rank stops here alike
    return 0;
  }
  if (job.parallel() && (!options.png.empty() || options.usesSensors()))
  {
    throw UsageError(std::string(options.png.empty() ? "--sensors and --work-plane" : "--png") +
      " under mpiexec: the ranks write the frames they solved, and pictures and sensors need "
      "every frame in one process: run it without mpiexec");
  }
  vtkNew<vtkMovingLightRadiosity> filter;
  configureFilter(options, filter);
  if (!options.png.empty())
  {
    PictureDisplay::checkAvailable();
  }

  // Every input is read and checked before anything is written.
  const Clock::time_point readingStarted = Clock::now();
  const std::uint64_t memoryLimit =
    options.memoryLimit ? static_cast<std::uint64_t>(*options.memoryLimit) << 20 : 0;
  const auto scene = options.usesEmbeddedScene() ? readEmbeddedFile("cornell_box.vtp")
                                                 : readSceneFile(options.scene, memoryLimit);
  if (options.sceneLightsItself() && !options.sky && !emits(scene, filter->GetEmissionArrayName()))
  {
    throw UsageError("--scene needs --light FILE or --light-material NAME, or surfaces that emit "
                     "(a cell array '" +
      std::string(filter->GetEmissionArrayName()) +
      "', or materials with Ke or an emissive colour): " + options.scene +
      " emits nothing, and the built-in light belongs to the Cornell box");
  }
  vtkSmartPointer<vtkPolyData> light;
  if (!options.usesSun() && !options.lightMaterial && !options.sceneLightsItself() &&
    !options.pointLight && !options.luminaire)
  {
    light = options.light.empty() ? readEmbeddedFile("cornell_light.vtp")
                                  : readSurfaceFile(options.light, "light", memoryLimit);
  }
  vtkSmartPointer<vtkPolyData> trajectory;
  if (options.sunPath)
  {
    trajectory = sunPathTrajectory(options);
  }
  else if (!options.weather.empty())
  {
    trajectory = weatherTrajectory(options);
  }
  else if (!options.sunDirections.empty())
  {
    trajectory = readSurfaceFile(options.sunDirections, "sun directions", memoryLimit);
  }
  else if (!options.trajectory.empty())
  {
    trajectory = readSurfaceFile(options.trajectory, "trajectory", memoryLimit);
  }
  else if (!options.from && !options.sceneLightsItself())
  {
    trajectory = readEmbeddedFile("cornell_trajectory.vtp");
  }
  vtkSmartPointer<vtkPolyData> sensors;
  if (!options.sensors.empty())
  {
    sensors = readSurfaceFile(options.sensors, "sensors", memoryLimit);
  }
  else if (options.workPlane)
  {
    sensors =
      workPlaneSensors(scene, options.zenith(), (*options.workPlane)[0], (*options.workPlane)[1],
        lightPositions(options, trajectory, scene, filter->GetEmissionArrayName()),
        options.usesSun() || options.sky.has_value(),
        // A weather year's 8760 frames of results: the trajectory's points (per light, when
        // there are several: an upper bound), the straight path's frames, or one (a sky, the
        // scene's own emitters).
        trajectory       ? static_cast<std::size_t>(trajectory->GetNumberOfPoints())
          : options.from ? static_cast<std::size_t>(std::max(filter->GetNumberOfPositions(), 1))
                         : std::size_t(1),
        memoryLimit);
  }
  StageTimes stages;
  stages.reading = secondsSince(readingStarted);
  if (options.sceneIsYUp() && !options.up &&
    (options.usesSun() || options.sky || options.workPlane || !options.lightDistribution.empty()))
  {
    std::cout << "the glTF scene is Y-up (the glTF standard): up is 0,1,0 and north 0,0,-1; "
                 "--up and --north change them"
              << std::endl;
  }
  if (sensors)
  {
    filter->SetInputData(vtkMovingLightRadiosity::SENSORS_PORT, sensors);
  }
  filter->SetInputData(vtkMovingLightRadiosity::SCENE_PORT, scene);
  if (light)
  {
    filter->SetInputData(vtkMovingLightRadiosity::LIGHT_PORT, light);
  }
  if (trajectory)
  {
    filter->SetInputData(vtkMovingLightRadiosity::TRAJECTORY_PORT, trajectory);
  }

  ProgressBar bar;
  vtkNew<vtkCallbackCommand> onProgress;
  onProgress->SetClientData(&bar);
  onProgress->SetCallback(
    [](vtkObject* caller, unsigned long, void* bar, void*)
    {
      auto* algorithm = static_cast<vtkMovingLightRadiosity*>(caller);
      if (Interrupted)
      {
        abortingTheFilter();
        algorithm->SetAbortExecute(1);
      }
      // The error estimate's messages (rounds, estimates) as lines above the bar.
      static std::string shown;
      const char* text = algorithm->GetProgressText();
      if (text && shown != text)
      {
        shown = text;
        static_cast<ProgressBar*>(bar)->finish();
        std::cout << shown << std::endl;
      }
      static_cast<ProgressBar*>(bar)->show(algorithm->GetProgress(), "solving");
    });
  const unsigned long solving = filter->AddObserver(vtkCommand::ProgressEvent, onProgress);
  // Errors and warnings go below the bar, not into it.
  vtkNew<vtkCallbackCommand> onMessage;
  onMessage->SetClientData(&bar);
  onMessage->SetCallback(
    [](vtkObject*, unsigned long event, void* bar, void* message)
    {
      static_cast<ProgressBar*>(bar)->finish();
      const char* text = static_cast<const char*>(message);
      if (event == vtkCommand::ErrorEvent)
      {
        vtkOutputWindow::GetInstance()->DisplayErrorText(text);
      }
      else
      {
        vtkOutputWindow::GetInstance()->DisplayWarningText(text);
      }
    });
  filter->AddObserver(vtkCommand::ErrorEvent, onMessage);
  filter->AddObserver(vtkCommand::WarningEvent, onMessage);

  filter->UpdateInformation();
  const std::vector<double> times = timeSteps(filter);

  // Where the results go is checked before the solve, which may take minutes: output names
  // taken by directories, directories that cannot be created or written.
  OutputTransaction output;
  const fs::path collection = options.output;
  const SeriesNaming naming(collection, times.size());
  const fs::path sensorCollection = sensorsCollectionOf(collection);
  const SeriesNaming sensorNaming(sensorCollection, times.size());
  checkNotADirectory(collection, "output");
  prepareDirectory(output, naming.directory);
  if (!options.stats.empty())
  {
    checkNotADirectory(options.stats, "statistics file");
    prepareDirectory(output, fs::path(options.stats).parent_path());
  }
  if (!options.png.empty())
  {
    prepareDirectory(output, options.png);
  }

  // A solve in several chunks streams: each chunk's frames are written as soon as they are
  // final, then freed (the filter keeps the last chunk's). Pictures and sensors need every
  // frame kept, and so does a solve in one chunk, whose frames are written after it.
  // Under mpiexec each rank gets the chunks it solved (when the ranks take whole chunks).
  const bool streaming = !sensors && options.png.empty();
  std::vector<FrameRecord> records;
  std::optional<FrameWriter> streamWriter; // destroyed before `output`, as below
  std::exception_ptr streamFailure;
  std::size_t framesReceived = 0;
  std::vector<std::size_t> streamedFrames;
  bool othersWrite = false;
  if (streaming)
  {
    filter->SetChunkObserver(
      [&](std::size_t f, vtkPolyData* elements)
      {
        ++framesReceived;
        // Under mpiexec with fewer chunks than ranks every rank gets every frame, starting
        // with the first, which ranks that take whole chunks leave to rank 0: rank 0 writes.
        othersWrite = othersWrite || (job.rank() > 0 && f == 0);
        if (streamFailure || Interrupted || othersWrite)
        {
          return;
        }
        try
        {
          if (!streamWriter)
          {
            streamWriter.emplace(writerThreads());
          }
          FrameRecord record;
          record.time = times[f];
          record.file = naming.frameName(f, ".vtu");
          recordLights(record, elements->GetFieldData());
          streamWriter->write(elements, times[f], output.stage(naming.directory / record.file));
          records.push_back(record);
          streamedFrames.push_back(f);
        }
        catch (...)
        {
          streamFailure = std::current_exception();
          abortingTheFilter();
          filter->SetAbortExecute(1);
        }
      });
  }
  if (job.parallel())
  {
    // Inputs read and outputs checked on every rank: the solve's collectives may start.
    OwesInputAgreement = false;
    agreeAcrossRanks(job);
  }
  const Clock::time_point solveStarted = Clock::now();
  vtkPolyData* first = nullptr;
  try
  {
    std::optional<InterruptWatcher> watcher;
    if (job.parallel())
    {
      watcher.emplace(filter);
    }
    // The solve; streamed, only the last chunk's frames are kept.
    first = frameAt(filter, streaming ? times.back() : times.front());
  }
  catch (...)
  {
    if (streamFailure)
    {
      std::rethrow_exception(streamFailure);
    }
    throw;
  }
  filter->SetChunkObserver({});
  const bool streamed = !records.empty();
  const double update = secondsSince(solveStarted);
  // Later updates only copy frames out of the filter's cache: their progress is not the solve's.
  filter->RemoveObserver(solving);
  bar.finish();
  if (!job.parallel()) // under mpiexec the ranks stop together, in writeRankFrames
  {
    throwIfInterrupted();
  }
  if (first->GetNumberOfCells() == 0 && !job.parallel())
  {
    throw InputError("the scene has no polygons or triangle strips to light: nothing to write");
  }
  // A copy: the next update clears the output's field data in place.
  vtkNew<vtkFieldData> statistics;
  statistics->ShallowCopy(first->GetFieldData());
  // The update of the Elements serves the Light output too: the lights as solved.
  PosedLight posedLight;
  posedLight.light = vtkSmartPointer<vtkPolyData>::New();
  posedLight.light->DeepCopy(filter->GetOutput(vtkMovingLightRadiosity::LIGHT_OUTPUT_PORT));
  vtkDataArray* remeshing = statistics->GetArray("SecondsRemeshing");
  stages.remeshing = remeshing ? std::min(remeshing->GetComponent(0, 0), update) : 0.0;
  // Streamed frames were converted and handed to the writers during the solve: writing.
  vtkDataArray* handedOn = streamed ? statistics->GetArray("SecondsStreaming") : nullptr;
  stages.writing =
    handedOn ? std::clamp(handedOn->GetComponent(0, 0), 0.0, update - stages.remeshing) : 0.0;
  stages.solving = update - stages.remeshing - stages.writing;

  const Clock::time_point writingStarted = Clock::now();
  std::vector<std::pair<double, std::string>> sensorEntries;
  if (job.parallel() && job.holders(framesReceived > 0).count > 0)
  {
    records = finishRankStream(job, times, naming, streamWriter, records, streamedFrames);
    if (job.rank() == 0)
    {
      for (const FrameRecord& record : records)
      {
        output.keep(naming.directory / record.file);
      }
    }
  }
  else if (job.parallel())
  {
    records = writeRankFrames(job, filter, times, naming, output);
    if (job.rank() == 0)
    {
      // The other ranks' frames are theirs to commit, before this rank's .pvd names them.
      for (const FrameRecord& record : records)
      {
        output.keep(naming.directory / record.file);
      }
    }
  }
  else if (streamed)
  {
    streamWriter->finish();
    if (records.size() != times.size())
    {
      throw InputError("the solve streamed " + std::to_string(records.size()) + " of " +
        std::to_string(times.size()) + " frames: nothing was written");
    }
  }
  else
  {
    // Destroyed before `output`: no frame is still being written when a failure rolls back.
    FrameWriter writer(writerThreads());
    for (std::size_t f = 0; f < times.size(); ++f)
    {
      throwIfInterrupted();
      vtkPolyData* elements = frameAt(filter, times[f]);
      FrameRecord record;
      record.time = times[f];
      record.file = naming.frameName(f, ".vtu");
      recordLights(record, elements->GetFieldData());
      writer.write(elements, times[f], output.stage(naming.directory / record.file));
      records.push_back(record);
      if (sensors)
      {
        // The update of the Elements serves the Sensors at that time too. Their field data
        // shares its arrays with the element frames in the writer threads, and an XML writer
        // caches ranges and information in the arrays it writes: the element frames are
        // written out first, so that two writers never touch the same array.
        writer.finish();
        sensorEntries.emplace_back(times[f], sensorNaming.frameName(f, ".vtp"));
        writeSensorFrame(filter->GetOutput(vtkMovingLightRadiosity::SENSORS_OUTPUT_PORT),
          output.stage(naming.directory / sensorEntries.back().second));
      }
      bar.show(double(f + 1) / double(times.size()), "writing frames");
    }
    writer.finish();
  }
  if (job.rank() == 0)
  {
    output.replaceSeries(naming.directory, naming.framePrefix(), ".vtu");
  }
  if (job.rank() == 0)
  {
    // An earlier run's sensors are part of the series this one replaces, with or without
    // sensors of its own.
    output.replaceSeries(naming.directory, sensorNaming.framePrefix(), ".vtp");
    if (sensors)
    {
      writeCollection(output.stage(sensorCollection), sensorEntries);
    }
    else
    {
      output.removeAtCommit(sensorCollection,
        [&sensorNaming](const fs::path& index)
        { return indexesOnly(index, sensorNaming.framePrefix(), ".vtp"); });
    }
  }
  stages.writing += secondsSince(writingStarted);

  if (!options.png.empty())
  {
    const Clock::time_point renderingStarted = Clock::now();
    const fs::path pictures = options.png;
    const PictureDisplay display; // outlives the renderer's connection to it
    // Scenes lit by the sun get an aerial view, their zenith up.
    const Triple zenith = options.zenith();
    FrameRenderer renderer(scene->GetBounds(), options.usesSun() ? zenith.data() : nullptr);
    if (!options.usesSun())
    {
      // The lit sides of the first, middle and last frames choose between the outside camera
      // and one inside a closed room.
      std::vector<std::size_t> samples = { 0, times.size() / 2, times.size() - 1 };
      samples.erase(std::unique(samples.begin(), samples.end()), samples.end());
      for (std::size_t f : samples)
      {
        renderer.sampleLighting(frameAt(filter, times[f]));
      }
      const FrameRenderer::View& view = renderer.chooseView();
      if (view.inside)
      {
        std::ostringstream line;
        line << std::setprecision(3) << "pictures from inside the scene, at (" << view.position[0]
             << ", " << view.position[1] << ", " << view.position[2]
             << ") looking along +z: lit sides fill " << 100 * view.litInside
             << "% of the view there, " << 100 * view.litOutside << "% from outside";
        bar.finish();
        std::cout << line.str() << std::endl;
      }
    }
    for (std::size_t f = 0; f < times.size(); ++f)
    {
      throwIfInterrupted();
      vtkPolyData* elements = frameAt(filter, times[f]);
      // The update of the Elements serves every output port at that time.
      vtkPolyData* posedLight = filter->GetOutput(vtkMovingLightRadiosity::LIGHT_OUTPUT_PORT);
      records[f].picture = (pictures / naming.frameName(f, ".png")).string();
      renderer.render(elements, posedLight, output.stage(records[f].picture));
      bar.show(double(f + 1) / double(times.size()), "rendering pictures");
    }
    output.replaceSeries(pictures, naming.framePrefix(), ".png");
    stages.rendering = secondsSince(renderingStarted);
  }

  // The index and the statistics: rank 0's under mpiexec.
  auto writeIndex = [&]
  {
    std::vector<std::pair<double, std::string>> entries;
    for (const FrameRecord& record : records)
    {
      entries.emplace_back(record.time, record.file);
    }
    const Clock::time_point collectionStarted = Clock::now();
    writeCollection(output.stage(collection), entries); // staged after its frames
    stages.writing += secondsSince(collectionStarted);
    stages.total = secondsSince(started);
    if (!options.stats.empty())
    {
      const fs::path statsPath = options.stats;
      writeStatisticsJson(output.stage(statsPath), options, filter, statistics, records, stages,
        posedLight, sensors ? sensors->GetNumberOfPoints() : 0);
    }
  };
  if (!job.parallel())
  {
    writeIndex();
    throwIfInterrupted();
    output.commit();
  }
  else
  {
    // Every rank's files are staged before any is renamed. Rank 0 must see the others' (one
    // folder on a file system they share), or its index would name frames it cannot reach.
    // Then all rename theirs, and only once every rank has may any drop the earlier files: a
    // rank that fails moves its own back, and the others move theirs back as they leave.
    std::string failure;
    if (job.rank() == 0)
    {
      failure = failureOf(
        [&]
        {
          for (const FrameRecord& record : records)
          {
            const fs::path frame = naming.directory / record.file;
            std::error_code error;
            if (!output.stages(frame) && !fs::exists(OutputTransaction::temporaryOf(frame), error))
            {
              throw InputError("rank 0 does not see '" + frame.string() +
                "', which another rank wrote: give every rank the same --output, in a folder "
                "on a file system all of them share (not a node's own disk), and start them "
                "in the same working folder; nothing was written");
            }
          }
          writeIndex();
        });
    }
    agreeAcrossRanks(job, failure);
    agreeAcrossRanks(job, failureOf([&] { output.moveIntoPlace(); }));
    output.finish();
  }
  bar.finish();

  const std::string errors = errorLine(statistics);
  std::cout << summaryLine(statistics) << (errors.empty() ? "" : "\n" + errors) << "\nwrote "
            << collection.string() << " and " << times.size()
            << (times.size() == 1 ? " frame" : " frames");
  if (!options.png.empty())
  {
    std::cout << ", pictures in " << options.png;
  }
  if (!options.stats.empty())
  {
    std::cout << ", statistics in " << options.stats;
  }
  if (sensors)
  {
    std::cout << ", " << sensors->GetNumberOfPoints() << " sensors in "
              << sensorCollection.string();
  }
  std::cout << "\n" << timeLine(stages) << std::endl;
  return 0;
}
}

int main(int argc, char** argv)
{
  installMessageWindow("moving-light-radiosity");
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  std::optional<RankJob> job;
  try
  {
    job.emplace(&argc, &argv);
  }
  catch (const std::exception& e)
  {
    printError(e.what());
    return ExitFailure;
  }
  if (job->rank() > 0)
  {
    // Rank 0 speaks for all: the ranks run alike, and a failure elsewhere reaches it named.
    quietMessages();
    if (!std::freopen("/dev/null", "w", stdout))
    {
      std::fclose(stdout);
    }
  }
  // A rank that fails before the others agree on their inputs meets them there.
  auto failed = [&](int code, const std::string& message)
  {
    if (job->parallel() && OwesInputAgreement)
    {
      OwesInputAgreement = false;
      job->agree(true, message);
    }
    return code;
  };
  try
  {
    return run(argc, argv, *job);
  }
  catch (const UsageError& e)
  {
    printError(std::string(e.what()) + " (see --help)");
    return failed(ExitUsage, e.what());
  }
  catch (const AlreadyReported&)
  {
    return failed(ExitFailure, lastVtkError().empty() ? "failed" : lastVtkError());
  }
  catch (const std::exception& e)
  {
    printError(e.what());
    return failed(ExitFailure, e.what());
  }
}
