// libFuzzer target: arbitrary bytes -> one input file, its format chosen by the first byte
// modulo 11 (or by MLR_FUZZ_FORMAT), in the order .vtp .obj .ply .stl .vtu .vtk .ies .ldt .gltf
// .glb .epw:
// - the six scene formats are read as the command line reads them, through the guarded reading
//   (Apps/GuardedRead; .obj and .ply by our vtkRadiositySceneReader with their materials), and
//   go to the vtkMovingLightRadiosity filter with a fixed light and a 2-frame trajectory, few
//   paths and a small memory limit;
// - .ies and .ldt are read by mlr::readPhotometricFile, whose distribution must then be finite
//   and sample where its density is positive;
// - .gltf and .glb are read by vtkRadiositySceneReader in this process, as ParaView runs it: a
//   crash there is a finding, not a refusal;
// - .epw is read by mlr::readWeatherFile, whose hours must then make frames with finite suns
//   and irradiances.
//
// A refused file (mlr::guarded::InputError: checks, VTK's errors, a reader that crashed or ran
// out of time in its child process; mlr::Error for a photometric file) or a filter error is a
// normal outcome. Findings are crashes, sanitizer reports in our code, exceptions escaping,
// hangs and memory over -rss_limit_mb.
// VTK's readers are not instrumented: a fault inside them shows as a crash of the reading
// process, and GuardedRead must turn it into a refusal. The reader's time limit here (1 s of
// CPU time, 4 s in all, plus 1 s per MiB) stays well under the fuzzer's -timeout, so that a
// reader that loops is refused, not reported as a hang: the replay in ctest must end.
#include "Error.h"
#include "GuardedRead.h"
#include "Photometry.h"
#include "WeatherFile.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkExecutive.h"
#include "vtkLogger.h"
#include "vtkMovingLightRadiosity.h"
#include "vtkNew.h"
#include "vtkObject.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkRadiositySceneReader.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace
{
namespace fs = std::filesystem;

[[noreturn]] void finding(const std::string& what)
{
  std::fprintf(stderr, "FUZZ FINDING: %s\n", what.c_str());
  std::abort();
}

/// What every input shares: a private directory for the file, the light and the trajectory.
struct Setup
{
  fs::path directory;
  vtkNew<vtkPolyData> light, trajectory;

  Setup()
  {
    // Quiet unless asked (GuardedRead counts VTK's errors either way).
    if (!std::getenv("MLR_FUZZ_VERBOSE"))
    {
      vtkObject::GlobalWarningDisplayOff();
      vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
    }
    char pattern[] = "/tmp/mlr-fuzz-readers-XXXXXX";
    if (!mkdtemp(pattern))
    {
      finding("cannot create a temporary directory");
    }
    this->directory = pattern;

    // A 0.2 m square light at z = 1 facing down, moving along x.
    vtkNew<vtkPoints> corners;
    corners->InsertNextPoint(-0.1, -0.1, 1);
    corners->InsertNextPoint(-0.1, 0.1, 1);
    corners->InsertNextPoint(0.1, 0.1, 1);
    corners->InsertNextPoint(0.1, -0.1, 1);
    vtkNew<vtkCellArray> square;
    const vtkIdType ids[4] = { 0, 1, 2, 3 };
    square->InsertNextCell(4, ids);
    this->light->SetPoints(corners);
    this->light->SetPolys(square);
    vtkNew<vtkPoints> positions;
    positions->InsertNextPoint(0, 0, 1);
    positions->InsertNextPoint(0.5, 0, 1);
    this->trajectory->SetPoints(positions);
  }

  ~Setup() { fs::remove_all(this->directory); }
};

/// A photometric file that reads must describe a finite, positive distribution whose samples
/// fall where its density is positive.
void checkPhotometricFile(const fs::path& path)
{
  mlr::Luminaire luminaire;
  try
  {
    luminaire = mlr::readPhotometricFile(path.string());
  }
  catch (const mlr::Error&)
  {
    return;
  }
  const mlr::IntensityDistribution& d = luminaire.distribution;
  if (!std::isfinite(luminaire.lumens) || !(luminaire.lumens > 0) ||
    !std::isfinite(d.maximumDensity()) || !(d.maximumDensity() > 0))
  {
    finding("a photometric file read with no finite, positive flux");
  }
  if (!std::isfinite(luminaire.width) || !std::isfinite(luminaire.length) ||
    !std::isfinite(luminaire.height) || luminaire.width < 0 || luminaire.length < 0 ||
    luminaire.height < 0)
  {
    finding("a photometric file read with a luminous opening that is negative or not finite");
  }
  for (int k = 0; k < 64; ++k)
  {
    const mlr::Vec3 v = d.sample((k + 0.5) / 64, std::fmod((k + 0.5) * 0.618033988749895, 1.0));
    const double f = d.density(v);
    if (!mlr::isFinite(v) || std::abs(mlr::length(v) - 1) > 1e-9 || !std::isfinite(f) || !(f > 0) ||
      f > d.maximumDensity() * (1 + 1e-9))
    {
      finding("a photometric distribution sampled a direction of zero, excessive or non-finite "
              "density");
    }
  }
}

/// A weather file that reads has a whole year, and its hours make finite frames.
void checkWeatherFile(const fs::path& path)
{
  mlr::WeatherFile file;
  try
  {
    file = mlr::readWeatherFile(path.string());
  }
  catch (const mlr::Error&)
  {
    return;
  }
  if (file.hours.size() != 8760 && file.hours.size() != 8784)
  {
    finding("a weather file read with other than a year of hours");
  }
  mlr::WeatherSelection selection;
  selection.firstMonth = 12;
  selection.firstDay = 30;
  selection.lastMonth = 1;
  selection.lastDay = 2;
  selection.includeNight = true;
  std::vector<mlr::WeatherFrame> frames;
  try
  {
    frames = mlr::weatherFrames(file, selection);
  }
  catch (const mlr::Error&)
  {
    return;
  }
  for (const mlr::WeatherFrame& f : frames)
  {
    if (!mlr::isFinite(f.sun.direction) || std::abs(mlr::length(f.sun.direction) - 1) > 1e-9 ||
      !(f.directNormal >= 0) || !(f.diffuseHorizontal >= 0) || f.dayOfYear < 1 || f.dayOfYear > 366)
    {
      finding("a weather file's hour made a frame with a bad sun, irradiance or day");
    }
  }
}
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  static Setup setup;
  static const char* const extensions[] = { ".vtp", ".obj", ".ply", ".stl", ".vtu", ".vtk", ".ies",
    ".ldt", ".gltf", ".glb", ".epw" };
  if (size == 0)
  {
    return 0;
  }
  // MLR_FUZZ_FORMAT (an extension without its dot) fixes the format, so that a run spends its
  // time on one reader; the first byte is still skipped, so the seeds read the same either way.
  static const int forced = [] {
    const char* format = std::getenv("MLR_FUZZ_FORMAT");
    for (int k = 0; format && k < 11; ++k)
    {
      if (std::string(".") + format == extensions[k])
      {
        return k;
      }
    }
    if (format)
    {
      finding(std::string("MLR_FUZZ_FORMAT=") + format + " is not one of vtp obj ply stl vtu vtk "
                                                          "ies ldt gltf glb epw");
    }
    return -1;
  }();
  const unsigned kind = forced >= 0 ? unsigned(forced) : data[0] % 11;
  const fs::path path = setup.directory / (std::string("scene") + extensions[kind]);
  {
    std::ofstream file(path, std::ios::binary | std::ios::trunc);
    file.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  if (kind == 6 || kind == 7)
  {
    checkPhotometricFile(path);
    return 0;
  }
  if (kind == 10)
  {
    checkWeatherFile(path);
    return 0;
  }

  vtkSmartPointer<vtkPolyData> scene;
  if (kind >= 8)
  {
    vtkNew<vtkRadiositySceneReader> reader;
    reader->SetFileName(path.string().c_str());
    if (!reader->GetExecutive()->Update())
    {
      return 0;
    }
    scene = reader->GetOutput();
  }
  else
  {
    try
    {
      mlr::guarded::ReadLimits limits;
      limits.time.baseSeconds = 1;
      scene = mlr::guarded::readSurfaceFile(path.string(), "scene", limits,
        [](const std::string& file, const std::string&) -> vtkSmartPointer<vtkAlgorithm>
        {
          auto reader = vtkSmartPointer<vtkRadiositySceneReader>::New();
          reader->SetFileName(file.c_str());
          return vtkRadiositySceneReader::CanReadFile(file.c_str()) ? reader : nullptr;
        });
    }
    catch (const mlr::guarded::InputError&)
    {
      return 0;
    }
  }

  vtkNew<vtkMovingLightRadiosity> filter;
  filter->SetInputData(vtkMovingLightRadiosity::SCENE_PORT, scene);
  filter->SetInputData(vtkMovingLightRadiosity::LIGHT_PORT, setup.light);
  filter->SetInputData(vtkMovingLightRadiosity::TRAJECTORY_PORT, setup.trajectory);
  filter->SetNumberOfPaths(300);
  filter->SetNumberOfThreads(1);
  filter->SetMemoryLimit(16); // MiB: refused rather than slow
  // About a hundred patches over the scene's extent, whatever its scale.
  const double diagonal = scene->GetLength();
  filter->SetPatchSize(std::isfinite(diagonal) && diagonal > 0 ? diagonal / 8 : 0.0);
  const bool solved = filter->UpdateTimeStep(0) != 0;

  vtkPolyData* elements = filter->GetOutput(vtkMovingLightRadiosity::ELEMENTS_PORT);
  if (!solved && elements->GetNumberOfCells() != 0)
  {
    finding("a failed update left cells in the output");
  }
  if (vtkDataArray* radiosity = elements->GetCellData()->GetArray("Radiosity"))
  {
    for (int c = 0; c < 3; ++c)
    {
      const double* range = radiosity->GetRange(c);
      if (!std::isfinite(range[0]) || !std::isfinite(range[1]) || range[0] < 0)
      {
        finding("the filter output radiosity that is negative, NaN or infinite");
      }
    }
  }
  return 0;
}
