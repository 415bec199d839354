// Inputs and probes shared by the tests of vtkMovingLightRadiosity.
#pragma once

#include "MovingLight.h"
#include "Scene.h"

#include "vtkCommand.h"
#include "vtkSmartPointer.h"

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

class vtkAlgorithm;
class vtkCallbackCommand;
class vtkDataObject;
class vtkFieldData;
class vtkMovingLightRadiosity;
class vtkPolyData;

namespace mlr::testing
{

/// A fresh folder for one test's files (named after `name`, which tests keep distinct),
/// removed with them at the end of the test.
struct TestFolder
{
  explicit TestFolder(const std::string& name)
    : path(std::filesystem::temp_directory_path() / ("mlr-test-" + name))
  {
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TestFolder()
  {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  const std::filesystem::path path;
};

/// Core's patch mesh as the filter's Scene input: triangles with a cell array Reflectance.
vtkSmartPointer<vtkPolyData> scenePolyData(const PatchMesh& mesh);

/// Light polygons as the filter's Light input.
vtkSmartPointer<vtkPolyData> lightPolyData(const std::vector<std::vector<Vec3>>& polygons);

/// Points (and, when given, a point array Time) as the filter's Trajectory input.
vtkSmartPointer<vtkPolyData> trajectoryPolyData(
  const std::vector<Vec3>& positions, const std::vector<double>& times = {});

/// The unit box of Core's tests, closed, inward normals, 4 cells per edge, grey 0.5, with a
/// 0.2 m light facing down near its top and `frames` positions on a diagonal below it.
struct BoxSetup
{
  vtkSmartPointer<vtkPolyData> scene, light, trajectory;
  std::vector<Vec3> positions;
};
BoxSetup closedBoxSetup(std::size_t frames);

/// A filter on `setup` with few paths and patches of the box's cell size: fast to solve.
vtkSmartPointer<vtkMovingLightRadiosity> fastFilter(const BoxSetup& setup);

/// The time steps the algorithm's output port 0 declares.
std::vector<double> timeSteps(vtkAlgorithm* algorithm);

/// The first value of the field data array `name`, or NaN when it is missing.
double fieldValue(vtkDataObject* data, const char* name);

/// The first string of the field data string array `name`, or "" when it is missing.
std::string stringValue(vtkFieldData* data, const char* name);

/// Twice the area times the unit normal (right-hand rule) of cell `cell` of a triangle mesh.
Vec3 triangleAreaVector(vtkPolyData* mesh, vtkIdType cell);

/// Area of cell `cell` of a triangle mesh.
double triangleArea(vtkPolyData* mesh, vtkIdType cell);

/// Records the errors and warnings an object reports (instead of printing them).
class MessageRecorder : public vtkCommand
{
public:
  static MessageRecorder* New() { return new MessageRecorder; }
  void Execute(vtkObject*, unsigned long event, void* data) override;
  /// Starts recording from `object`.
  void watch(vtkObject* object);

  std::vector<std::string> errors, warnings;
  /// All errors in one string, for assertions.
  std::string allErrors() const;
  std::string allWarnings() const;
};

/// Every progress value an algorithm reports, and where in them an abort was asked for: at the
/// first value past `threshold`, as a ParaView progress observer or a user pressing Stop.
struct ProgressLog
{
  double threshold = 2.0; // above any progress: no abort unless set
  std::vector<double> values;
  std::size_t abortedAfter = 0; // values reported before the abort, the one asking included
  bool aborted = false;
};

/// Logs `algorithm`'s ProgressEvents into `log` through `command` (which sets AbortExecute at
/// the threshold).
void logProgress(vtkAlgorithm* algorithm, ProgressLog& log, vtkCallbackCommand* command);

/// `values` from index `from` on, separated by commas, for assertion messages.
std::string listed(const std::vector<double>& values, std::size_t from);

} // namespace mlr::testing
