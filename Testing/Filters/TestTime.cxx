// Time steps are light positions: one solve serves every time until something changes.
#include "FilterTestSupport.h"

#include "vtkCallbackCommand.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkMovingLightRadiosity.h"
#include "vtkNew.h"
#include "vtkPlaneSource.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

using namespace mlr;
using namespace mlr::testing;

namespace
{
double dataTime(vtkPolyData* output)
{
  return output->GetInformation()->Get(vtkDataObject::DATA_TIME_STEP());
}

std::vector<float> arrayValues(vtkPolyData* output, const char* name)
{
  vtkDataArray* array = output->GetCellData()->GetArray(name);
  std::vector<float> values;
  for (vtkIdType i = 0; array && i < array->GetNumberOfValues(); ++i)
  {
    values.push_back(static_cast<float>(array->GetComponent(i / 3, static_cast<int>(i % 3))));
  }
  return values;
}

/// How well the direct light on the floor (z = 0) matches a small light at `light`: the
/// correlation of DirectRadiosity with the point-light shape h^2 / (h^2 + d^2)^2.
double floorMatch(vtkPolyData* elements, const Vec3& light)
{
  vtkDataArray* direct = elements->GetCellData()->GetArray("DirectRadiosity");
  std::vector<double> measured, predicted;
  for (vtkIdType c = 0; c < elements->GetNumberOfCells(); ++c)
  {
    double bounds[6];
    elements->GetCellBounds(c, bounds);
    if (bounds[5] > 1e-6)
    {
      continue;
    }
    const double dx = 0.5 * (bounds[0] + bounds[1]) - light.x;
    const double dy = 0.5 * (bounds[2] + bounds[3]) - light.y;
    const double h2 = light.z * light.z;
    measured.push_back(direct->GetComponent(c, 1));
    predicted.push_back(h2 / std::pow(h2 + dx * dx + dy * dy, 2));
  }
  const auto mean = [](const std::vector<double>& v)
  {
    double s = 0;
    for (double x : v)
    {
      s += x;
    }
    return s / double(v.size());
  };
  const double mm = mean(measured), mp = mean(predicted);
  double sxy = 0, sxx = 0, syy = 0;
  for (std::size_t i = 0; i < measured.size(); ++i)
  {
    sxy += (measured[i] - mm) * (predicted[i] - mp);
    sxx += (measured[i] - mm) * (measured[i] - mm);
    syy += (predicted[i] - mp) * (predicted[i] - mp);
  }
  return sxy / std::sqrt(sxx * syy);
}
}

TEST(FilterTime, TimeStepsAreTheTrajectoryPointsOrItsTimeArray)
{
  BoxSetup setup = closedBoxSetup(5);
  auto filter = fastFilter(setup);
  EXPECT_EQ(timeSteps(filter), (std::vector<double>{ 0, 1, 2, 3, 4 }));
  vtkInformation* info = filter->GetOutputInformation(1);
  const double* range = info->Get(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
  EXPECT_EQ(range[0], 0);
  EXPECT_EQ(range[1], 4);

  const std::vector<double> times = { 0.5, 1.0, 2.5, 4.0, 8.0 };
  filter->SetInputData(
    vtkMovingLightRadiosity::TRAJECTORY_PORT, trajectoryPolyData(setup.positions, times));
  EXPECT_EQ(timeSteps(filter), times);
}

TEST(FilterTime, WithoutTrajectoryTheLightMovesFromPathStartToPathEnd)
{
  BoxSetup setup = closedBoxSetup(1);
  auto filter = fastFilter(setup);
  filter->RemoveAllInputConnections(vtkMovingLightRadiosity::TRAJECTORY_PORT);
  filter->SetPathStart(0.3, 0.3, 0.9);
  filter->SetPathEnd(0.7, 0.5, 0.9);
  filter->SetNumberOfPositions(3);
  ASSERT_EQ(timeSteps(filter), (std::vector<double>{ 0, 1, 2 }));
  ASSERT_TRUE(filter->UpdateTimeStep(1));
  vtkDataArray* position = filter->GetOutput()->GetFieldData()->GetArray("LightPosition");
  ASSERT_NE(position, nullptr);
  EXPECT_NEAR(position->GetComponent(0, 0), 0.5, 1e-12);
  EXPECT_NEAR(position->GetComponent(0, 1), 0.4, 1e-12);
  EXPECT_NEAR(position->GetComponent(0, 2), 0.9, 1e-12);
}

TEST(FilterTime, EachTimeShowsItsOwnFrameAndLightPosition)
{
  BoxSetup setup = closedBoxSetup(4);
  auto filter = fastFilter(setup);
  filter->SetNumberOfPaths(100000);
  const std::vector<double> times = timeSteps(filter);
  ASSERT_EQ(times.size(), 4u);
  for (std::size_t f = 0; f < times.size(); ++f)
  {
    ASSERT_TRUE(filter->UpdateTimeStep(times[f]));
    for (int port : { 0, 1 })
    {
      EXPECT_EQ(dataTime(filter->GetOutput(port)), times[f]) << "port " << port;
    }
    vtkPolyData* elements = filter->GetOutput(0);
    EXPECT_EQ(fieldValue(elements, "FrameIndex"), double(f));
    vtkDataArray* position = elements->GetFieldData()->GetArray("LightPosition");
    ASSERT_NE(position, nullptr);
    EXPECT_NEAR(position->GetComponent(0, 0), setup.positions[f].x, 1e-12);
    EXPECT_NEAR(position->GetComponent(0, 1), setup.positions[f].y, 1e-12);
    // The light on the floor is that of this frame's position, not of another one.
    std::size_t best = 0;
    for (std::size_t k = 1; k < setup.positions.size(); ++k)
    {
      if (floorMatch(elements, setup.positions[k]) > floorMatch(elements, setup.positions[best]))
      {
        best = k;
      }
    }
    EXPECT_EQ(best, f);
    EXPECT_GT(floorMatch(elements, setup.positions[f]), 0.9) << "frame " << f;
  }
  EXPECT_EQ(filter->GetSolveCount(), 1);
}

TEST(FilterTime, TimesBetweenStepsShowTheStepAtOrBelow)
{
  BoxSetup setup = closedBoxSetup(3);
  auto filter = fastFilter(setup);
  filter->SetInputData(
    vtkMovingLightRadiosity::TRAJECTORY_PORT, trajectoryPolyData(setup.positions, { 1, 2, 4 }));
  const std::vector<std::pair<double, double>> cases = { { 3.9, 2 }, { 4.5, 4 }, { 0.0, 1 },
    { 2.0, 2 }, { 2.0 - 1e-12, 2 } };
  for (const auto& [requested, shown] : cases)
  {
    ASSERT_TRUE(filter->UpdateTimeStep(requested));
    EXPECT_EQ(dataTime(filter->GetOutput()), shown) << "requested " << requested;
  }
}

TEST(FilterTime, StepsAskedForAsWrittenShowThatStep)
{
  // A Time array in single precision holds 0.1 as 0.10000000149: asked for 0.1, 0.2 and 0.3
  // as written, the steps show, not the steps before them.
  BoxSetup setup = closedBoxSetup(3);
  auto filter = fastFilter(setup);
  vtkSmartPointer<vtkPolyData> trajectory = trajectoryPolyData(setup.positions);
  vtkNew<vtkFloatArray> time;
  time->SetName("Time");
  for (const float t : { 0.1f, 0.2f, 0.3f })
  {
    time->InsertNextValue(t);
  }
  trajectory->GetPointData()->AddArray(time);
  filter->SetInputData(vtkMovingLightRadiosity::TRAJECTORY_PORT, trajectory);
  for (const double written : { 0.1, 0.2, 0.3 })
  {
    ASSERT_TRUE(filter->UpdateTimeStep(written));
    EXPECT_EQ(dataTime(filter->GetOutput()), static_cast<float>(written)) << written;
  }
  // Steps closer than any rounding: each shows itself, and a request between them the one
  // at or below.
  filter->SetInputData(vtkMovingLightRadiosity::TRAJECTORY_PORT,
    trajectoryPolyData(setup.positions, { 10.0, 10.0000001, 1000.0 }));
  const std::vector<std::pair<double, double>> cases = { { 10.0, 10.0 }, { 10.0000001, 10.0000001 },
    { 10.00000005, 10.0 }, { 999.9999999, 1000.0 } };
  for (const auto& [requested, shown] : cases)
  {
    ASSERT_TRUE(filter->UpdateTimeStep(requested));
    EXPECT_EQ(dataTime(filter->GetOutput()), shown) << "requested " << requested;
  }
}

TEST(FilterTime, SwitchingTimeServesTheCacheWithoutSolvingOrUpdatingInputs)
{
  BoxSetup setup = closedBoxSetup(3);
  auto filter = fastFilter(setup);
  ASSERT_TRUE(filter->UpdateTimeStep(1));
  const std::vector<float> frame1 = arrayValues(filter->GetOutput(), "Radiosity");
  ASSERT_FALSE(frame1.empty());
  EXPECT_EQ(filter->GetSolveCount(), 1);
  const vtkMTimeType sceneTime = filter->GetInputDataObject(0, 0)->GetMTime();

  for (double t : { 2.0, 0.0, 1.0, 2.0, 1.0 })
  {
    ASSERT_TRUE(filter->UpdateTimeStep(t));
    EXPECT_EQ(filter->GetSolveCount(), 1) << "time " << t;
    EXPECT_EQ(fieldValue(filter->GetOutput(), "SolveCount"), 1);
    EXPECT_EQ(fieldValue(filter->GetOutput(), "FrameIndex"), t);
  }
  EXPECT_EQ(arrayValues(filter->GetOutput(), "Radiosity"), frame1);
  ASSERT_TRUE(filter->UpdateTimeStep(0));
  EXPECT_NE(arrayValues(filter->GetOutput(), "Radiosity"), frame1);
  EXPECT_EQ(filter->GetInputDataObject(0, 0)->GetMTime(), sceneTime);
}

TEST(FilterTime, CachedChunksSolveADroppedChunkAgainWithTheSameValues)
{
  // 12 frames in chunks of 3 (m = 1; chunks finish frames 0-1, 2-4, 5-7, 8-11). A cache of
  // one chunk against a cache of all four: the same arrays at every time step, asked in an
  // order that drops and brings back chunks; each miss solves one chunk again, a hit none.
  BoxSetup setup = closedBoxSetup(12);
  auto all = fastFilter(setup);
  all->SetFramesPerChunk(3);
  all->SetCachedChunks(4);
  auto one = fastFilter(setup);
  one->SetFramesPerChunk(3);
  one->SetCachedChunks(1);
  int again = 0;
  for (const double t : { 0.0, 11.0, 1.0, 3.0, 4.0, 2.0, 11.0, 9.0, 6.0, 0.0 })
  {
    ASSERT_TRUE(all->UpdateTimeStep(t));
    ASSERT_TRUE(one->UpdateTimeStep(t));
    for (const char* name : { "Radiosity", "Irradiance", "RadiosityStdError", "Color" })
    {
      const std::vector<float> expected = arrayValues(all->GetOutput(), name);
      ASSERT_FALSE(expected.empty()) << name;
      EXPECT_EQ(arrayValues(one->GetOutput(), name), expected) << name << " at time " << t;
    }
    EXPECT_EQ(fieldValue(one->GetOutput(), "FrameIndex"), t);
    EXPECT_EQ(fieldValue(one->GetOutput(), "RelativeErrorP95"),
      fieldValue(all->GetOutput(), "RelativeErrorP95"));
    EXPECT_EQ(one->GetSolveCount(), 1);
    // The first solve keeps the chunk asked for (0-1), not the last (8-11): no solve again.
    static const std::vector<int> expectedAgain = { 0, 1, 2, 3, 3, 3, 4, 4, 5, 6 };
    EXPECT_EQ(fieldValue(one->GetOutput(), "ChunksSolvedAgain"), expectedAgain[again++])
      << "time " << t;
  }
  EXPECT_EQ(fieldValue(all->GetOutput(), "ChunksSolvedAgain"), 0);
}

TEST(FilterTime, AChunkSolvedAgainRepeatsTheRoundsATimeLimitCut)
{
  // A target no solve reaches, stopped by a TimeLimit: each chunk runs the batches its share
  // of the time allowed. Solved again when asked for after the cache dropped it, a chunk runs
  // the same batches, whatever the time it takes now, and shows the same values.
  BoxSetup setup = closedBoxSetup(12);
  auto filter = fastFilter(setup);
  filter->SetFramesPerChunk(3);
  filter->SetCachedChunks(1);
  filter->SetErrorBatches(4);
  filter->SetTargetRelativeError(1e-4);
  filter->SetTimeLimit(1.0);
  ASSERT_TRUE(filter->UpdateTimeStep(3));
  std::map<std::string, std::vector<float>> first;
  for (const char* name : { "Radiosity", "RadiosityStdError" })
  {
    first[name] = arrayValues(filter->GetOutput(), name);
    ASSERT_FALSE(first[name].empty()) << name;
  }
  const double p95 = fieldValue(filter->GetOutput(), "RelativeErrorP95");
  ASSERT_EQ(stringValue(filter->GetOutput()->GetFieldData(), "StoppedBy"), "time limit");
  ASSERT_TRUE(filter->UpdateTimeStep(9));
  ASSERT_TRUE(filter->UpdateTimeStep(3));
  EXPECT_EQ(fieldValue(filter->GetOutput(), "ChunksSolvedAgain"), 2);
  for (const auto& [name, values] : first)
  {
    EXPECT_EQ(arrayValues(filter->GetOutput(), name.c_str()), values) << name;
  }
  EXPECT_EQ(fieldValue(filter->GetOutput(), "RelativeErrorP95"), p95);
  EXPECT_EQ(filter->GetSolveCount(), 1);
}

TEST(FilterTime, AChunkOverlapIsKeptWhenADroppedChunkIsSolvedAgain)
{
  // 12 frames in chunks of 4 overlapping by 2 (the default would be 1): a cache of one chunk
  // against one of all three gives the same arrays at every time step, the dropped chunks
  // solved again with the same overlap; ChunkOverlap more than half a chunk is refused.
  BoxSetup setup = closedBoxSetup(12);
  auto all = fastFilter(setup);
  all->SetFramesPerChunk(4);
  all->SetChunkOverlap(2);
  all->SetCachedChunks(3);
  auto one = fastFilter(setup);
  one->SetFramesPerChunk(4);
  one->SetChunkOverlap(2);
  one->SetCachedChunks(1);
  for (const double t : { 0.0, 11.0, 3.0, 5.0, 1.0 })
  {
    ASSERT_TRUE(all->UpdateTimeStep(t));
    ASSERT_TRUE(one->UpdateTimeStep(t));
    EXPECT_EQ(
      arrayValues(one->GetOutput(), "Radiosity"), arrayValues(all->GetOutput(), "Radiosity"))
      << "time " << t;
    EXPECT_EQ(fieldValue(one->GetOutput(), "ChunkOverlap"), 2);
  }
  EXPECT_GT(fieldValue(one->GetOutput(), "ChunksSolvedAgain"), 0);
  one->SetChunkOverlap(3);
  vtkNew<MessageRecorder> messages;
  messages->watch(one);
  EXPECT_EQ(one->UpdateTimeStep(0), 0);
  EXPECT_NE(
    messages->allErrors().find("ChunkOverlap is 3, more than half of FramesPerChunk (4): give 0"),
    std::string::npos)
    << messages->allErrors();
}

TEST(FilterTime, TheFiltersTimeIsNotPassedUpstream)
{
  BoxSetup setup = closedBoxSetup(3);
  auto filter = fastFilter(setup);
  vtkNew<vtkPlaneSource> light;
  light->SetOrigin(0.4, 0.4, 0.9);
  light->SetPoint1(0.4, 0.6, 0.9); // normal (P1 - O) x (P2 - O) = -z: facing down
  light->SetPoint2(0.6, 0.4, 0.9);
  filter->SetInputConnection(vtkMovingLightRadiosity::LIGHT_PORT, light->GetOutputPort());
  int executions = 0;
  vtkNew<vtkCallbackCommand> count;
  count->SetClientData(&executions);
  count->SetCallback([](vtkObject*, unsigned long, void* n, void*) { ++*static_cast<int*>(n); });
  light->AddObserver(vtkCommand::StartEvent, count);

  for (double t : { 0.0, 2.0, 1.0, 0.0 })
  {
    ASSERT_TRUE(filter->UpdateTimeStep(t));
  }
  EXPECT_EQ(executions, 1);
  EXPECT_EQ(filter->GetSolveCount(), 1);
  EXPECT_GT(filter->GetOutput()->GetNumberOfCells(), 0);
}

TEST(FilterTime, ChangingAPropertyOrAnInputSolvesAgain)
{
  BoxSetup setup = closedBoxSetup(3);
  auto filter = fastFilter(setup);
  ASSERT_TRUE(filter->UpdateTimeStep(0));
  ASSERT_EQ(filter->GetSolveCount(), 1);
  const std::vector<float> seed0 = arrayValues(filter->GetOutput(), "Radiosity");

  filter->SetSeed(0); // the same value: nothing changed
  ASSERT_TRUE(filter->UpdateTimeStep(1));
  EXPECT_EQ(filter->GetSolveCount(), 1);

  filter->SetSeed(7);
  ASSERT_TRUE(filter->UpdateTimeStep(0));
  EXPECT_EQ(filter->GetSolveCount(), 2);
  EXPECT_NE(arrayValues(filter->GetOutput(), "Radiosity"), seed0);
  EXPECT_EQ(fieldValue(filter->GetOutput(), "SolveCount"), 2);

  filter->SetLightPower(50, 50, 50);
  ASSERT_TRUE(filter->UpdateTimeStep(0));
  EXPECT_EQ(filter->GetSolveCount(), 3);

  setup.light->Modified(); // an input that changed
  ASSERT_TRUE(filter->UpdateTimeStep(2));
  EXPECT_EQ(filter->GetSolveCount(), 4);

  ASSERT_TRUE(filter->UpdateTimeStep(1));
  EXPECT_EQ(filter->GetSolveCount(), 4);
}

TEST(FilterTime, PredictedSpeedupIsEquationFourOfTheSolve)
{
  // n (1 + lambda (l - 1)) + k n over n + lambda (l - 1) + k, for the solve's own n frames,
  // k and lambda and the l it measured: not the defaults, and not another solve's.
  BoxSetup setup = closedBoxSetup(2);
  auto filter = fastFilter(setup);
  filter->SetGatheringRatio(0.5);
  filter->SetFirstBounceSurvival(0.6);
  ASSERT_TRUE(filter->UpdateTimeStep(0));
  vtkPolyData* elements = filter->GetOutput(0);
  const double n = fieldValue(elements, "Frames"), l = fieldValue(elements, "MeanPathLength");
  ASSERT_EQ(n, 2);
  EXPECT_GT(l, 1.5) << "walks in a closed box of reflectance 0.5 average about two hits";
  const double walk = 0.6 * (l - 1);
  EXPECT_NEAR(
    fieldValue(elements, "PredictedSpeedup"), (2 * (1 + walk) + 0.5 * 2) / (2 + walk + 0.5), 1e-12);
}

TEST(FilterTime, OutputsCarryTheDocumentedArrays)
{
  BoxSetup setup = closedBoxSetup(2);
  auto filter = fastFilter(setup);
  ASSERT_TRUE(filter->UpdateTimeStep(0));
  vtkPolyData* elements = filter->GetOutput(0);
  vtkPolyData* patches = filter->GetOutput(1);
  ASSERT_GT(elements->GetNumberOfCells(), 0);
  EXPECT_EQ(elements->GetNumberOfCells(), 4 * patches->GetNumberOfCells());
  for (const char* name : { "Radiosity", "DirectRadiosity", "IndirectRadiosity", "RadiosityFront",
         "RadiosityBack", "Reflectance" })
  {
    vtkDataArray* array = elements->GetCellData()->GetArray(name);
    ASSERT_NE(array, nullptr) << name;
    EXPECT_EQ(array->GetNumberOfComponents(), 3) << name;
  }
  ASSERT_NE(elements->GetCellData()->GetArray("PatchId"), nullptr);
  EXPECT_EQ(elements->GetCellData()->GetArray("PatchId")->GetNumberOfComponents(), 1);
  for (const char* name : { "Radiosity", "Reflectance" })
  {
    ASSERT_NE(patches->GetCellData()->GetArray(name), nullptr) << name;
  }
  for (const char* name :
    { "Frames", "Patches", "Elements", "PathsPerFrame", "PathsCast", "ShootingRays", "ShadowRays",
      "GatheringRays", "SecondsRemeshing", "SecondsShooting", "SecondsGathering", "SecondsTotal",
      "ReuseShooting", "ReuseGathering", "PredictedSpeedup", "FrameIndex", "SolveCount" })
  {
    EXPECT_FALSE(std::isnan(fieldValue(elements, name))) << name;
  }
  EXPECT_EQ(fieldValue(elements, "Frames"), 2);
  EXPECT_EQ(fieldValue(elements, "Elements"), elements->GetNumberOfCells());
  EXPECT_EQ(fieldValue(elements, "Patches"), patches->GetNumberOfCells());

  filter->TwoSidedOff();
  ASSERT_TRUE(filter->UpdateTimeStep(0));
  EXPECT_EQ(filter->GetOutput(0)->GetCellData()->GetArray("RadiosityFront"), nullptr);
  EXPECT_NE(filter->GetOutput(0)->GetCellData()->GetArray("Radiosity"), nullptr);
}
