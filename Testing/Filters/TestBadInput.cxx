// Bad input and aborts: an error naming what to fix, empty outputs, no crash, no stale result.
#include "FilterTestSupport.h"

#include "vtkCallbackCommand.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkMovingLightRadiosity.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"
#include "vtkStripper.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

using namespace mlr;
using namespace mlr::testing;

namespace
{
struct FilterRun
{
  bool succeeded = false;
  vtkSmartPointer<MessageRecorder> messages;
  vtkIdType elements = 0, patches = 0;
};

FilterRun runFilter(vtkMovingLightRadiosity* filter)
{
  FilterRun run;
  run.messages = vtkSmartPointer<MessageRecorder>::New();
  run.messages->watch(filter);
  run.succeeded = filter->UpdateTimeStep(0) != 0;
  run.elements = filter->GetOutput(0)->GetNumberOfCells();
  run.patches = filter->GetOutput(1)->GetNumberOfCells();
  filter->RemoveAllObservers();
  return run;
}

void expectError(const FilterRun& run, const std::string& expected)
{
  EXPECT_FALSE(run.succeeded);
  ASSERT_FALSE(run.messages->errors.empty()) << "no error reported; expected: " << expected;
  EXPECT_NE(run.messages->allErrors().find(expected), std::string::npos)
    << run.messages->allErrors();
  EXPECT_EQ(run.elements, 0);
  EXPECT_EQ(run.patches, 0);
}

/// Sets AbortExecute from the first progress event past 10%, as a user pressing Stop would
/// once the solve is under way, and notes when.
class AbortMidway
{
public:
  using Clock = std::chrono::steady_clock;
  explicit AbortMidway(vtkMovingLightRadiosity* filter)
    : Filter(filter)
  {
    this->Command->SetClientData(this);
    this->Command->SetCallback(
      [](vtkObject*, unsigned long, void* data, void*)
      {
        auto* self = static_cast<AbortMidway*>(data);
        if (!self->aborted && self->Filter->GetProgress() > 0.1)
        {
          self->aborted = true;
          self->abortedAt = Clock::now();
          self->Filter->SetAbortExecute(1);
        }
      });
    filter->AddObserver(vtkCommand::ProgressEvent, this->Command);
  }
  bool aborted = false;
  Clock::time_point abortedAt{};

private:
  vtkMovingLightRadiosity* Filter;
  vtkNew<vtkCallbackCommand> Command;
};

void setReflectance(vtkPolyData* scene, vtkAbstractArray* array)
{
  scene->GetCellData()->RemoveArray("Reflectance");
  array->SetName("Reflectance");
  scene->GetCellData()->AddArray(array);
}
}

TEST(FilterBadInput, ReflectanceWithTwoComponents)
{
  BoxSetup setup = closedBoxSetup(2);
  vtkNew<vtkFloatArray> rho;
  rho->SetNumberOfComponents(2);
  rho->SetNumberOfTuples(setup.scene->GetNumberOfCells());
  rho->FillValue(0.5f);
  setReflectance(setup.scene, rho);
  expectError(runFilter(fastFilter(setup)), "Reflectance has 2 components");
}

TEST(FilterBadInput, ReflectanceThatIsNotNumeric)
{
  BoxSetup setup = closedBoxSetup(2);
  vtkNew<vtkStringArray> rho;
  rho->SetNumberOfValues(setup.scene->GetNumberOfCells());
  setReflectance(setup.scene, rho);
  expectError(runFilter(fastFilter(setup)), "give a numeric array");
}

TEST(FilterBadInput, ReflectanceOutOfRangeNamesTheCell)
{
  BoxSetup setup = closedBoxSetup(2);
  setup.scene->GetCellData()->GetArray("Reflectance")->SetComponent(7, 1, 1.2);
  expectError(runFilter(fastFilter(setup)), "Scene cell 7 has Reflectance (0.5, 1.2, 0.5)");
}

TEST(FilterBadInput, MissingReflectanceIsGreyWithAWarning)
{
  BoxSetup setup = closedBoxSetup(2);
  setup.scene->GetCellData()->RemoveArray("Reflectance");
  auto filter = fastFilter(setup);
  const FilterRun run = runFilter(filter);
  EXPECT_TRUE(run.succeeded);
  EXPECT_NE(run.messages->allWarnings().find("no cell array Reflectance"), std::string::npos);
  vtkDataArray* rho = filter->GetOutput()->GetCellData()->GetArray("Reflectance");
  ASSERT_NE(rho, nullptr);
  EXPECT_FLOAT_EQ(static_cast<float>(rho->GetRange(0)[0]), 0.5f);
  EXPECT_FLOAT_EQ(static_cast<float>(rho->GetRange(2)[1]), 0.5f);
}

TEST(FilterBadInput, OneComponentReflectanceIsGrey)
{
  BoxSetup setup = closedBoxSetup(2);
  vtkNew<vtkDoubleArray> grey;
  grey->SetNumberOfTuples(setup.scene->GetNumberOfCells());
  grey->FillValue(0.3);
  setReflectance(setup.scene, grey);
  auto filter = fastFilter(setup);
  const FilterRun run = runFilter(filter);
  EXPECT_TRUE(run.succeeded) << run.messages->allErrors();
  vtkDataArray* rho = filter->GetOutput()->GetCellData()->GetArray("Reflectance");
  ASSERT_NE(rho, nullptr);
  for (int c = 0; c < 3; ++c)
  {
    EXPECT_FLOAT_EQ(static_cast<float>(rho->GetRange(c)[0]), 0.3f);
    EXPECT_FLOAT_EQ(static_cast<float>(rho->GetRange(c)[1]), 0.3f);
  }
}

TEST(FilterBadInput, NaNPoints)
{
  BoxSetup setup = closedBoxSetup(2);
  setup.scene->GetPoints()->SetPoint(3, std::numeric_limits<double>::quiet_NaN(), 0, 0);
  expectError(runFilter(fastFilter(setup)), "NaN");
}

TEST(FilterBadInput, LightWithoutPolygons)
{
  BoxSetup setup = closedBoxSetup(2);
  vtkNew<vtkPolyData> line;
  line->SetPoints(setup.light->GetPoints());
  vtkNew<vtkCellArray> lines;
  const vtkIdType ids[2] = { 0, 1 };
  lines->InsertNextCell(2, ids);
  line->SetLines(lines);
  setup.light = line;
  expectError(runFilter(fastFilter(setup)), "the light has no polygon");
}

TEST(FilterBadInput, NegativeLightPower)
{
  BoxSetup setup = closedBoxSetup(2);
  auto filter = fastFilter(setup);
  filter->SetLightPower(1, -1, 1);
  expectError(runFilter(filter), "light power");
}

TEST(FilterBadInput, TrajectoryTimesMustIncreaseAndNoEarlierResultStays)
{
  BoxSetup setup = closedBoxSetup(3);
  auto filter = fastFilter(setup);
  ASSERT_TRUE(filter->UpdateTimeStep(0));
  ASSERT_GT(filter->GetOutput()->GetNumberOfCells(), 0);

  filter->SetInputData(
    vtkMovingLightRadiosity::TRAJECTORY_PORT, trajectoryPolyData(setup.positions, { 0, 2, 1 }));
  auto messages = vtkSmartPointer<MessageRecorder>::New();
  messages->watch(filter);
  EXPECT_FALSE(filter->UpdateTimeStep(0));
  EXPECT_NE(messages->allErrors().find("Time must increase strictly"), std::string::npos)
    << messages->allErrors();
  EXPECT_EQ(filter->GetOutput(0)->GetNumberOfCells(), 0);
  EXPECT_EQ(filter->GetOutput(1)->GetNumberOfCells(), 0);
}

TEST(FilterBadInput, TrajectoryWithoutPoints)
{
  BoxSetup setup = closedBoxSetup(3);
  setup.trajectory = trajectoryPolyData({});
  auto filter = fastFilter(setup);
  auto messages = vtkSmartPointer<MessageRecorder>::New();
  messages->watch(filter);
  EXPECT_FALSE(filter->UpdateTimeStep(0));
  EXPECT_NE(messages->allErrors().find("the Trajectory has no points"), std::string::npos);
}

TEST(FilterBadInput, MemoryLimitRefusesTheSolveBeforeAllocating)
{
  BoxSetup setup = closedBoxSetup(1);
  auto filter = fastFilter(setup);
  filter->RemoveAllInputConnections(vtkMovingLightRadiosity::TRAJECTORY_PORT);
  filter->SetPathStart(0.3, 0.3, 0.9);
  filter->SetPathEnd(0.7, 0.7, 0.9);
  filter->SetNumberOfPositions(5000);
  filter->SetMemoryLimit(1);
  expectError(runFilter(filter), "memory limit");
}

TEST(FilterBadInput, EmptySceneGivesEmptyOutputsWithoutError)
{
  BoxSetup setup = closedBoxSetup(2);
  setup.scene = vtkSmartPointer<vtkPolyData>::New();
  const FilterRun run = runFilter(fastFilter(setup));
  EXPECT_TRUE(run.succeeded);
  EXPECT_TRUE(run.messages->errors.empty()) << run.messages->allErrors();
  EXPECT_EQ(run.elements, 0);
}

TEST(FilterBadInput, VerticesAndLinesAreIgnoredWithAWarning)
{
  BoxSetup setup = closedBoxSetup(2);
  vtkNew<vtkCellArray> verts;
  const vtkIdType vertex = 0;
  verts->InsertNextCell(1, &vertex);
  setup.scene->SetVerts(verts);
  // Cell data follows the cells: one more (leading) value for the vertex.
  vtkNew<vtkFloatArray> rho;
  rho->SetNumberOfComponents(3);
  rho->InsertNextTuple3(0.9, 0.9, 0.9);
  vtkDataArray* old = setup.scene->GetCellData()->GetArray("Reflectance");
  for (vtkIdType i = 0; i < old->GetNumberOfTuples(); ++i)
  {
    rho->InsertNextTuple(old->GetTuple(i));
  }
  setReflectance(setup.scene, rho);
  const FilterRun run = runFilter(fastFilter(setup));
  EXPECT_TRUE(run.succeeded);
  EXPECT_NE(run.messages->allWarnings().find("ignored 1 vertex and 0 lines"), std::string::npos);
  EXPECT_GT(run.elements, 0);
}

TEST(FilterBadInput, TriangleStripsAreSurfaces)
{
  BoxSetup setup = closedBoxSetup(2);
  setup.scene->GetCellData()->RemoveArray("Reflectance"); // strips lose the per-cell values
  vtkNew<vtkStripper> stripper;
  stripper->SetInputData(setup.scene);
  stripper->Update();
  vtkPolyData* strips = stripper->GetOutput();
  ASSERT_GT(strips->GetNumberOfStrips(), 0);

  auto fromTriangles = fastFilter(setup);
  const FilterRun reference = runFilter(fromTriangles);
  setup.scene = strips;
  const FilterRun run = runFilter(fastFilter(setup));
  EXPECT_TRUE(run.succeeded) << run.messages->allErrors();
  // The same surface, so about the same patches; and all strip triangles face inward as the
  // polygons did: the box stays lit on the inside (its lit side is the front).
  EXPECT_NEAR(double(run.patches), double(reference.patches), 0.1 * double(reference.patches));
}

TEST(FilterBadInput, AbortStopsQuicklyWithEmptyOutputsAndRecovers)
{
  BoxSetup setup = closedBoxSetup(5);
  auto filter = fastFilter(setup);
  filter->SetNumberOfPaths(50000000); // tens of seconds if it ran to the end

  AbortMidway state(filter);
  const FilterRun run = runFilter(filter);
  const double seconds =
    std::chrono::duration<double>(AbortMidway::Clock::now() - state.abortedAt).count();
  ASSERT_TRUE(state.aborted);
  // 0.5 s on a quiet machine; ten times that so that load cannot change the verdict.
  EXPECT_LT(seconds, 5.0);
  expectError(run, "aborted");
  EXPECT_EQ(filter->GetSolveCount(), 0);

  // Nothing stale is kept: the next update solves again and succeeds.
  filter->RemoveAllObservers();
  filter->SetNumberOfPaths(20000);
  const FilterRun again = runFilter(filter);
  EXPECT_TRUE(again.succeeded) << again.messages->allErrors();
  EXPECT_GT(again.elements, 0);
  EXPECT_EQ(filter->GetSolveCount(), 1);
}

TEST(FilterBadInput, AnAbortHoldsUntilAPropertyChanges)
{
  BoxSetup setup = closedBoxSetup(3);
  auto filter = fastFilter(setup);
  filter->SetNumberOfPaths(50000000); // tens of seconds if anything solved it again
  AbortMidway state(filter);
  expectError(runFilter(filter), "aborted");
  ASSERT_TRUE(state.aborted);
  // The abort is spent: the flag is clear and no output is marked ABORTED, which would make
  // the next request of any port run the solve again.
  EXPECT_EQ(filter->GetAbortExecute(), 0);
  for (int port = 0; port < filter->GetNumberOfOutputPorts(); ++port)
  {
    EXPECT_EQ(filter->GetOutputInformation(port)->Get(vtkAlgorithm::ABORTED()), 0) << port;
  }

  // Another port, as a proxy's UpdatePipeline asks next: nothing runs.
  auto messages = vtkSmartPointer<MessageRecorder>::New();
  messages->watch(filter);
  filter->Update(vtkMovingLightRadiosity::PATCHES_PORT);
  EXPECT_TRUE(messages->errors.empty()) << messages->allErrors();
  // Another time step runs the filter again, which repeats the abort and solves nothing.
  const std::vector<double> steps = timeSteps(filter);
  ASSERT_GT(steps.size(), 1u);
  EXPECT_FALSE(filter->UpdateTimeStep(steps.back()));
  EXPECT_NE(messages->allErrors().find("the last solve was aborted"), std::string::npos)
    << messages->allErrors();
  EXPECT_EQ(filter->GetOutput(0)->GetNumberOfCells(), 0);
  EXPECT_EQ(filter->GetSolveCount(), 0);
  filter->RemoveAllObservers();

  // Asking to abort between updates does not move the MTime (on several ranks, that rank
  // alone would solve again) and stops the next solve.
  const vtkMTimeType before = filter->GetMTime();
  filter->SetAbortExecute(1);
  EXPECT_EQ(filter->GetMTime(), before);
  filter->SetNumberOfPaths(20000);
  expectError(runFilter(filter), "aborted");
  EXPECT_EQ(filter->GetAbortExecute(), 0);
  EXPECT_EQ(filter->GetSolveCount(), 0);

  // A change solves again.
  filter->SetNumberOfPaths(20001);
  const FilterRun again = runFilter(filter);
  EXPECT_TRUE(again.succeeded) << again.messages->allErrors();
  EXPECT_GT(again.elements, 0);
  EXPECT_EQ(filter->GetSolveCount(), 1);
}

TEST(FilterBadInput, NoProgressIsReportedAfterAnAbort)
{
  // VTK's executive reports 1.0 at the end of every execution, aborted or not, which ParaView
  // shows as done: an aborted update must end at the value its abort came from.
  BoxSetup setup = closedBoxSetup(5);
  auto filter = fastFilter(setup);
  filter->SetNumberOfPaths(2000000);
  ProgressLog log;
  log.threshold = 0.2;
  vtkNew<vtkCallbackCommand> command;
  logProgress(filter, log, command);
  auto messages = vtkSmartPointer<MessageRecorder>::New();
  messages->watch(filter);
  EXPECT_FALSE(filter->UpdateTimeStep(0));
  ASSERT_TRUE(log.aborted) << listed(log.values, 0);
  EXPECT_EQ(log.values.size(), log.abortedAfter)
    << "reported after the abort: " << listed(log.values, log.abortedAfter);
  for (double value : log.values)
  {
    EXPECT_LT(value, 1.0) << listed(log.values, 0);
  }
  EXPECT_GT(log.values.back(), 0.2);
  EXPECT_NE(messages->allErrors().find("aborted"), std::string::npos) << messages->allErrors();
  EXPECT_DOUBLE_EQ(filter->GetProgress(), log.values.back());
  for (int port = 0; port < filter->GetNumberOfOutputPorts(); ++port)
  {
    EXPECT_EQ(filter->GetOutput(port)->GetNumberOfCells(), 0) << port;
  }

  // Another time step repeats the abort's error without solving: no 1.0 either.
  log.values.clear();
  EXPECT_FALSE(filter->UpdateTimeStep(timeSteps(filter).back()));
  for (double value : log.values)
  {
    EXPECT_LT(value, 1.0) << listed(log.values, 0);
  }

  // An abort asked for before the update stops it before anything is reported.
  filter->SetNumberOfPaths(2000001);
  log.values.clear();
  filter->SetAbortExecute(1);
  EXPECT_FALSE(filter->UpdateTimeStep(0));
  EXPECT_TRUE(log.values.empty()) << listed(log.values, 0);
  EXPECT_EQ(filter->GetSolveCount(), 0);

  // An update that runs to its end still reports its progress up to 1.0.
  filter->SetNumberOfPaths(20000);
  log.values.clear();
  EXPECT_TRUE(filter->UpdateTimeStep(0)) << messages->allErrors();
  ASSERT_FALSE(log.values.empty());
  EXPECT_EQ(log.values.front(), 0.0);
  EXPECT_EQ(log.values.back(), 1.0);
  filter->RemoveAllObservers();
}

TEST(FilterBadInput, AnErrorIsRepeatedWithoutSolvingUntilSomethingChanges)
{
  BoxSetup setup = closedBoxSetup(3);
  setup.scene->GetCellData()->GetArray("Reflectance")->SetComponent(0, 0, 1.5);
  auto filter = fastFilter(setup);
  expectError(runFilter(filter), "Scene cell 0");
  auto messages = vtkSmartPointer<MessageRecorder>::New();
  messages->watch(filter);
  EXPECT_FALSE(filter->UpdateTimeStep(timeSteps(filter).back()));
  EXPECT_NE(messages->allErrors().find("Scene cell 0"), std::string::npos) << messages->allErrors();
  filter->RemoveAllObservers();
  EXPECT_EQ(filter->GetSolveCount(), 0);
}

TEST(FilterBadInput, AFixedInputSolvesAfterAnError)
{
  BoxSetup setup = closedBoxSetup(2);
  setup.scene->GetCellData()->GetArray("Reflectance")->SetComponent(0, 0, 1.5);
  auto filter = fastFilter(setup);
  expectError(runFilter(filter), "Scene cell 0");
  setup.scene->GetCellData()->GetArray("Reflectance")->SetComponent(0, 0, 0.5);
  setup.scene->GetCellData()->GetArray("Reflectance")->Modified();
  const FilterRun run = runFilter(filter);
  EXPECT_TRUE(run.succeeded) << run.messages->allErrors();
  EXPECT_GT(run.elements, 0);
}
