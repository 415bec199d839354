// The filter's output arrays keep Core's energy balance: a closed box absorbs all the power.
#include "FilterTestSupport.h"

#include "GeneratedScenes.h"

#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkMovingLightRadiosity.h"
#include "vtkPolyData.h"

#include <gtest/gtest.h>

using namespace mlr;
using namespace mlr::testing;

namespace
{
/// sum_i A_i (1 - rho_i) / rho_i B_i over the cells, from the output's arrays.
Rgb absorbed(vtkPolyData* elements, const std::vector<const char*>& sides)
{
  vtkDataArray* rho = elements->GetCellData()->GetArray("Reflectance");
  Rgb total;
  for (vtkIdType c = 0; c < elements->GetNumberOfCells(); ++c)
  {
    const double area = triangleArea(elements, c);
    for (const char* side : sides)
    {
      vtkDataArray* radiosity = elements->GetCellData()->GetArray(side);
      for (int k = 0; k < 3; ++k)
      {
        const double r = rho->GetComponent(c, k);
        total[k] += area * (1 - r) / r * radiosity->GetComponent(c, k);
      }
    }
  }
  return total;
}
}

TEST(FilterEnergyBalance, ClosedBoxAbsorbsAllPowerInEveryFrame)
{
  // Walls of different colours, so that channels and walls weigh differently (as in Core's
  // test), read through the filter's inputs and outputs instead of Core's structures.
  const std::vector<Rgb> walls = { Rgb(0.6, 0.2, 0.3), Rgb(0.3, 0.6, 0.2), Rgb(0.5, 0.5, 0.5),
    Rgb(0.7, 0.4, 0.6), Rgb(0.4, 0.3, 0.7), Rgb(0.55, 0.65, 0.45) };
  BoxSetup setup = closedBoxSetup(4);
  setup.scene = scenePolyData(scenes::closedBox(6, true, walls));
  auto filter = fastFilter(setup);
  filter->SetPatchSize(1.0 / 6.0);
  filter->SetNumberOfPaths(400000);
  const Rgb power(3, 5, 7);
  filter->SetLightPower(power.r, power.g, power.b);

  const std::vector<double> times = timeSteps(filter);
  ASSERT_EQ(times.size(), 4u);
  for (std::size_t f = 0; f < times.size(); ++f)
  {
    ASSERT_TRUE(filter->UpdateTimeStep(times[f]));
    vtkPolyData* elements = filter->GetOutput(0);
    ASSERT_GT(elements->GetNumberOfCells(), 0);
    const Rgb bothSides = absorbed(elements, { "RadiosityFront", "RadiosityBack" });
    // Inward normals: the outside of the box gets nothing, so the lit side alone balances too.
    const Rgb litSide = absorbed(elements, { "Radiosity" });
    for (int k = 0; k < 3; ++k)
    {
      EXPECT_NEAR(bothSides[k] / power[k], 1.0, 0.01) << "frame " << f << " channel " << k;
      EXPECT_NEAR(litSide[k] / power[k], 1.0, 0.01) << "frame " << f << " channel " << k;
    }
  }
  EXPECT_EQ(filter->GetSolveCount(), 1);
}
