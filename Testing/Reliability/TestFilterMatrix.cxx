// The bad-input matrix for vtkMovingLightRadiosity: one row per kind of bad input,
// each asserting the outcome (an error naming the problem, or a result with a warning), that
// a failed update leaves both outputs empty (no partial result) and that it takes seconds at
// most. The command line's rows (files, output folders, signals) are in test_cli_matrix.py.
#include "FilterTestSupport.h"
#include "ReliabilitySupport.h"

#include "GeneratedScenes.h"

#include "vtkCallbackCommand.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkMovingLightRadiosity.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

using namespace mlr;
using namespace mlr::testing;
using namespace mlr::reliability;

namespace
{
using Clock = std::chrono::steady_clock;

enum class Outcome
{
  Error,       ///< the update fails with `text` in the errors, both outputs empty
  Result,      ///< the update succeeds with cells (and `text` in the warnings, if given)
  EmptyResult, ///< the update succeeds with empty outputs (and `text` in the warnings)
};

/// The inputs and the filter of one row; setUp changes them from the closed box default.
struct Case
{
  BoxSetup setup = closedBoxSetup(3);
  vtkSmartPointer<vtkMovingLightRadiosity> filter;
  /// Seconds after the update starts at which AbortExecute is set (from the next progress
  /// event: what a user pressing Abort gets); negative for never.
  double abortAfter = -1;
};

struct Row
{
  const char* name;
  std::function<void(Case&)> setUp;
  Outcome outcome;
  std::string text;
  double seconds = 10; ///< the row must finish within this (sanitizer builds: three times)
  std::function<void(Case&)> check = {}; ///< more assertions on the outputs
};

vtkSmartPointer<vtkPolyData> polyData(
  const std::vector<Vec3>& points, const std::vector<std::vector<vtkIdType>>& polys)
{
  vtkNew<vtkPoints> vtkPoints;
  vtkPoints->SetDataTypeToDouble();
  for (const Vec3& p : points)
  {
    vtkPoints->InsertNextPoint(p.x, p.y, p.z);
  }
  vtkNew<vtkCellArray> cells;
  for (const auto& cell : polys)
  {
    cells->InsertNextCell(static_cast<vtkIdType>(cell.size()), cell.data());
  }
  auto data = vtkSmartPointer<vtkPolyData>::New();
  data->SetPoints(vtkPoints);
  data->SetPolys(cells);
  return data;
}

/// A soup as the filter's Scene input (no Reflectance: grey, with a warning).
vtkSmartPointer<vtkPolyData> soupPolyData(const PolygonSoup& soup)
{
  std::vector<std::vector<vtkIdType>> cells;
  for (const auto& polygon : soup.polygons)
  {
    cells.emplace_back(polygon.begin(), polygon.end());
  }
  return polyData(soup.points, cells);
}

void setReflectanceOfCell(Case& c, vtkIdType cell, double r, double g, double b)
{
  c.setup.scene->GetCellData()->GetArray("Reflectance")->SetTuple3(cell, r, g, b);
}

double maximumRadiosity(vtkPolyData* output)
{
  vtkDataArray* radiosity = output->GetCellData()->GetArray("Radiosity");
  double maximum = -1;
  for (int c = 0; radiosity && c < 3; ++c)
  {
    maximum = std::max(maximum, radiosity->GetRange(c)[1]);
  }
  return maximum;
}

const double NaN = std::numeric_limits<double>::quiet_NaN();
const double Inf = std::numeric_limits<double>::infinity();

std::vector<Row> rows()
{
  return {
    { "EmptyScene", [](Case& c) { c.setup.scene = vtkSmartPointer<vtkPolyData>::New(); },
      Outcome::EmptyResult, "" },
    { "SceneOfOnlyLinesAndPoints",
      [](Case& c)
      {
        vtkNew<vtkPolyData> scene;
        scene->SetPoints(c.setup.scene->GetPoints());
        vtkNew<vtkCellArray> verts, lines;
        const vtkIdType vertex = 0, line[3] = { 1, 2, 3 };
        verts->InsertNextCell(1, &vertex);
        lines->InsertNextCell(3, line);
        scene->SetVerts(verts);
        scene->SetLines(lines);
        c.setup.scene = scene;
      },
      Outcome::EmptyResult, "ignored 1 vertex and 1 line" },
    { "OneTriangle",
      [](Case& c) {
        c.setup.scene = polyData({ { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } }, { { 0, 1, 2 } });
      },
      Outcome::Result, "no cell array Reflectance", 10,
      [](Case& c) { EXPECT_GT(maximumRadiosity(c.filter->GetOutput(0)), 0); } },
    { "AllDegenerateTriangles",
      [](Case& c)
      {
        c.setup.scene = polyData({ { 0, 0, 0 }, { 1, 0, 0 }, { 2, 0, 0 }, { 0, 1, 0 } },
          { { 0, 1, 2 }, { 3, 3, 3 }, { 0, 0, 1 }, { 2, 1, 0 } });
      },
      Outcome::Error, "the scene has no polygon with an area" },
    { "NaNCoordinates", [](Case& c) { c.setup.scene->GetPoints()->SetPoint(5, 0.5, NaN, 0.5); },
      Outcome::Error, "1 point with NaN or infinite coordinates" },
    { "InfiniteCoordinates",
      [](Case& c)
      {
        c.setup.scene->GetPoints()->SetPoint(5, Inf, 0, 0);
        c.setup.scene->GetPoints()->SetPoint(6, 0, -Inf, 0);
      },
      Outcome::Error, "2 points with NaN or infinite coordinates" },
    { "TenMillionDuplicatedPoints",
      [](Case& c)
      {
        // 10^7 points, three distinct positions: 3.3 million copies of one triangle.
        vtkNew<vtkPoints> points;
        points->SetDataTypeToFloat();
        points->SetNumberOfPoints(10000000);
        const float corners[3][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } };
        for (vtkIdType i = 0; i < 10000000; ++i)
        {
          points->SetPoint(i, corners[i % 3]);
        }
        vtkNew<vtkCellArray> triangles;
        triangles->AllocateExact(3333333, 3 * 3333333);
        for (vtkIdType i = 0; i + 2 < 10000000; i += 3)
        {
          const vtkIdType ids[3] = { i, i + 1, i + 2 };
          triangles->InsertNextCell(3, ids);
        }
        auto scene = vtkSmartPointer<vtkPolyData>::New();
        scene->SetPoints(points);
        scene->SetPolys(triangles);
        c.setup.scene = scene;
      },
      Outcome::Result, "ignored 3333332 duplicate polygons", 20 },
    { "ReflectanceOfOne", [](Case& c) { setReflectanceOfCell(c, 4, 1, 1, 1); }, Outcome::Error,
      "Scene cell 4 has Reflectance (1, 1, 1): every value must be >= 0 and < 1" },
    { "NegativeReflectance", [](Case& c) { setReflectanceOfCell(c, 0, 0.5, -0.25, 0.5); },
      Outcome::Error, "Scene cell 0 has Reflectance (0.5, -0.25, 0.5)" },
    { "NaNReflectance", [](Case& c) { setReflectanceOfCell(c, 2, NaN, 0.5, 0.5); }, Outcome::Error,
      "Scene cell 2 has Reflectance (nan, 0.5, 0.5)" },
    { "LightWithZeroArea",
      [](Case& c)
      {
        c.setup.light =
          polyData({ { 0.4, 0.5, 0.9 }, { 0.5, 0.5, 0.9 }, { 0.6, 0.5, 0.9 } }, { { 0, 1, 2 } });
      },
      Outcome::Error, "is degenerate (zero area)" },
    { "LightFacingAwayFromTheScene",
      [](Case& c)
      {
        // An open floor below a light that faces up: no light ever reaches it.
        PatchMesh floor;
        scenes::addGriddedQuad(floor, { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, 4, 4, Rgb(0.5));
        c.setup.scene = scenePolyData(floor);
        auto up = scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2);
        std::reverse(up[0].begin(), up[0].end());
        c.setup.light = lightPolyData(up);
      },
      Outcome::Result, "no light reached the scene", 10,
      [](Case& c) { EXPECT_EQ(maximumRadiosity(c.filter->GetOutput(0)), 0.0); } },
    { "TrajectoryOfNoPoint", [](Case& c) { c.setup.trajectory = trajectoryPolyData({}); },
      Outcome::Error, "the Trajectory has no points" },
    { "TrajectoryOfOnePoint",
      [](Case& c) {
        c.setup.trajectory = trajectoryPolyData({ { 0.5, 0.5, 0.9 } });
      },
      Outcome::Result, "", 10, [](Case& c) { EXPECT_EQ(timeSteps(c.filter).size(), 1u); } },
    { "TenThousandFramesOnALargeScene",
      [](Case& c)
      {
        // 200,000 triangles at a patch size giving ~85,000 patches: ~180 GB for 10,000
        // frames, refused before remeshing starts.
        c.setup.scene = soupPolyData(sphereSoup(100));
        std::vector<Vec3> positions;
        for (int i = 0; i < 10000; ++i)
        {
          positions.emplace_back(-0.3 + 0.6 * i / 9999.0, 0, 0);
        }
        c.setup.trajectory = trajectoryPolyData(positions);
        c.setup.light = lightPolyData(scenes::squareLightFacingDown({ 0, 0, 0 }, 0.2));
        c.filter->SetPatchSize(0.02);
      },
      // "about": refused on the patch count expected before remeshing, not after it.
      Outcome::Error, "(10000 frames x (about", 5,
      [](Case& c) { EXPECT_EQ(c.filter->GetPatchSize(), 0.02); } },
    { "ManyFramesOverTheMemoryLimitSuggestKeepingFewer",
      [](Case& c)
      {
        // Every frame is kept unless CachedChunks says otherwise: the refusal names it.
        std::vector<Vec3> positions;
        for (int i = 0; i < 20000; ++i)
        {
          positions.emplace_back(0.2 + 0.6 * i / 19999.0, 0.5, 0.9);
        }
        c.setup.trajectory = trajectoryPolyData(positions);
        c.filter->SetMemoryLimit(64);
      },
      Outcome::Error, "keep fewer frames in memory (the filter's CachedChunks", 5 },
    { "LargeSceneOverTheMemoryLimitIsRefusedBeforeCopying",
      [](Case& c)
      {
        c.setup.scene = soupPolyData(sphereSoup(100)); // ~20 MB as a soup
        c.filter->SetMemoryLimit(8);
      },
      Outcome::Error,
      "the Scene has 200000 cells on 100002 points: taking them for remeshing needs an estimated",
      2 },
    // Out-of-range numbers are kept as given and refused by name before anything is solved.
    { "PathsZeroIsRefusedByName", [](Case& c) { c.filter->SetNumberOfPaths(0); }, Outcome::Error,
      "NumberOfPaths is 0: give paths per frame from 1", 10,
      [](Case& c) { EXPECT_EQ(c.filter->GetNumberOfPaths(), 0); } },
    { "PathsTwoToThe62AreRefusedByName",
      [](Case& c) { c.filter->SetNumberOfPaths(vtkIdType(1) << 62); }, Outcome::Error,
      "NumberOfPaths is 4611686018427387904: give" },
    { "PathsAtTheMaximumAreAbortable",
      [](Case& c)
      {
        c.filter->SetNumberOfPaths(100000000000LL);
        c.abortAfter = 0.3; // 10^11 paths would take days
      },
      Outcome::Error, "aborted", 10 },
    { "NegativeSeedIsRefusedByName", [](Case& c) { c.filter->SetSeed(-1); }, Outcome::Error,
      "Seed is -1: give 0 or a positive integer" },
    { "NoPositionIsRefusedByName",
      [](Case& c)
      {
        c.setup.trajectory = nullptr;
        c.filter->SetNumberOfPositions(0);
      },
      Outcome::Error, "NumberOfPositions is 0: give 1 to 100000" },
    { "NaNPatchSizeIsRefusedByName",
      [](Case& c) { c.filter->SetPatchSize(std::numeric_limits<double>::quiet_NaN()); },
      Outcome::Error, "PatchSize is nan: give 0" },
    { "WideSpotIsRefusedByName", [](Case& c) { c.filter->SetSpotHalfAngle(200); }, Outcome::Error,
      "SpotHalfAngle is 200: give 0 (no spot) up to 180 degrees" },
    { "NegativeExposureBeyondTheRangeIsRefusedByName", [](Case& c) { c.filter->SetExposure(-21); },
      Outcome::Error, "Exposure is -21: give -20 to 20 EV" },
    { "NegativeFluxIsRefusedByName", [](Case& c) { c.filter->SetLightFluxLumens(-800); },
      Outcome::Error, "LightFluxLumens is -800: give 0" },
    { "AbortMidSolve",
      [](Case& c)
      {
        c.filter->SetNumberOfPaths(50000000);
        c.abortAfter = 0.4;
      },
      Outcome::Error, "aborted" },
    { "AbortMidRemeshing",
      [](Case& c)
      {
        c.setup.scene = soupPolyData(sphereSoup(100));
        c.setup.light = lightPolyData(scenes::squareLightFacingDown({ 0, 0, 0 }, 0.2));
        c.filter->SetPatchSize(0);
        c.abortAfter = 0.8; // well inside remeshing's first pass
      },
      Outcome::Error, "aborted" },
  };
}

void PrintTo(const Row& row, std::ostream* os)
{
  *os << row.name;
}

class FilterMatrix : public ::testing::TestWithParam<Row>
{
};

TEST_P(FilterMatrix, Row)
{
  const Row& row = GetParam();
  Case c;
  // The filter is made first so that rows can change its properties; their input changes
  // are connected after.
  c.filter = fastFilter(c.setup);
  row.setUp(c);
  c.filter->SetInputData(vtkMovingLightRadiosity::SCENE_PORT, c.setup.scene);
  c.filter->SetInputData(vtkMovingLightRadiosity::LIGHT_PORT, c.setup.light);
  c.filter->SetInputData(vtkMovingLightRadiosity::TRAJECTORY_PORT, c.setup.trajectory);

  auto messages = vtkSmartPointer<MessageRecorder>::New();
  messages->watch(c.filter);
  struct AbortState
  {
    vtkMovingLightRadiosity* filter;
    Clock::time_point start, at;
    double after;
    bool aborted = false;
  } abort{ c.filter, Clock::now(), {}, c.abortAfter };
  vtkNew<vtkCallbackCommand> onProgress;
  onProgress->SetClientData(&abort);
  onProgress->SetCallback(
    [](vtkObject*, unsigned long, void* data, void*)
    {
      auto* s = static_cast<AbortState*>(data);
      if (s->after >= 0 && !s->aborted &&
        std::chrono::duration<double>(Clock::now() - s->start).count() >= s->after)
      {
        s->aborted = true;
        s->at = s->start +
          std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s->after));
        s->filter->SetAbortExecute(1);
      }
    });
  c.filter->AddObserver(vtkCommand::ProgressEvent, onProgress);

  abort.start = Clock::now();
  const bool succeeded = c.filter->UpdateTimeStep(0) != 0;
  const Clock::time_point end = Clock::now();
  const double seconds = std::chrono::duration<double>(end - abort.start).count();
  const vtkIdType elements = c.filter->GetOutput(0)->GetNumberOfCells();
  const vtkIdType patches = c.filter->GetOutput(1)->GetNumberOfCells();

  const double bound = row.seconds * (UnderAddressSanitizer ? 3 : 1);
  EXPECT_LT(seconds, bound) << "took " << seconds << " s";
  switch (row.outcome)
  {
    case Outcome::Error:
      EXPECT_FALSE(succeeded);
      EXPECT_NE(messages->allErrors().find(row.text), std::string::npos)
        << "errors: " << messages->allErrors();
      EXPECT_EQ(elements, 0) << "a failed update left a partial result";
      EXPECT_EQ(patches, 0) << "a failed update left a partial result";
      break;
    case Outcome::Result:
    case Outcome::EmptyResult:
      EXPECT_TRUE(succeeded) << messages->allErrors();
      EXPECT_TRUE(messages->errors.empty()) << messages->allErrors();
      EXPECT_NE(messages->allWarnings().find(row.text), std::string::npos)
        << "warnings: " << messages->allWarnings();
      if (row.outcome == Outcome::Result)
      {
        EXPECT_GT(elements, 0);
        EXPECT_GT(patches, 0);
      }
      else
      {
        EXPECT_EQ(elements, 0);
        EXPECT_EQ(patches, 0);
      }
      break;
  }
  if (c.abortAfter >= 0)
  {
    ASSERT_TRUE(abort.aborted) << "finished before the abort";
    const double latency = std::chrono::duration<double>(end - abort.at).count();
    std::printf("%s: aborted %.3f s after it was asked\n", row.name, latency);
    EXPECT_LT(latency, CancelLatencyBound);
  }
  if (row.check)
  {
    row.check(c);
  }
}

INSTANTIATE_TEST_SUITE_P(BadInput, FilterMatrix, ::testing::ValuesIn(rows()),
  [](const ::testing::TestParamInfo<Row>& info) { return std::string(info.param.name); });
}
