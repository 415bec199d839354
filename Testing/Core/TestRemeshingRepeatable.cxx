// The same soup remeshes to the same bits whatever the heap looks like. CGAL's
// autorefinement breaks ties between boxes by their addresses, so the order of the pieces it
// cut a floor into, and their triangulation where points are cocircular, followed the
// allocations made before it: the command line remeshed a box standing on a floor into 3098
// patches in most runs and 3092 in a few.
#include "Remeshing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace mlr;

namespace
{
/// A 12 x 12 floor, its diagonal through the footprint's corners or not, and an open-bottomed
/// box of float32 coordinates standing on it, as a user's VTK file gives it.
PolygonSoup boxOnFloor(double x0, double y0)
{
  const double side = static_cast<double>(0.6f);
  const double x1 = static_cast<double>(static_cast<float>(x0 + side));
  const double y1 = static_cast<double>(static_cast<float>(y0 + side));
  const double top = side;
  PolygonSoup soup;
  soup.points = { { -6, -6, 0 }, { 6, -6, 0 }, { 6, 6, 0 }, { -6, 6, 0 }, // floor
    { x0, y0, top }, { x1, y0, top }, { x1, y1, top }, { x0, y1, top },   // lid
    { x0, y0, 0 }, { x1, y0, 0 }, { x1, y1, 0 }, { x0, y1, 0 } };         // foot
  soup.polygons = { { 0, 1, 2, 3 }, { 4, 5, 6, 7 }, { 8, 9, 5, 4 }, { 9, 10, 6, 5 },
    { 10, 11, 7, 6 }, { 11, 8, 4, 7 } };
  soup.materials.assign(soup.polygons.size(), Material());
  return soup;
}

/// A 4 x 4 floor crossed by a UV sphere of 40 x 20 quads, off the floor's diagonal: a curved
/// contact line cutting many floor and sphere triangles.
PolygonSoup sphereThroughFloor()
{
  constexpr double Pi = 3.14159265358979323846;
  constexpr std::uint32_t Around = 40, Down = 20;
  PolygonSoup soup;
  soup.points = { { -2, -2, 0 }, { 2, -2, 0 }, { 2, 2, 0 }, { -2, 2, 0 } };
  soup.polygons = { { 0, 1, 2, 3 } };
  for (std::uint32_t j = 0; j <= Down; ++j)
  {
    for (std::uint32_t i = 0; i < Around; ++i)
    {
      const double theta = Pi * j / Down, phi = 2 * Pi * i / Around;
      soup.points.push_back({ 0.7 * std::sin(theta) * std::cos(phi) + 0.013,
        0.7 * std::sin(theta) * std::sin(phi) - 0.021, 0.3 + 0.7 * std::cos(theta) });
    }
  }
  auto at = [](std::uint32_t i, std::uint32_t j) { return 4 + j * Around + i % Around; };
  for (std::uint32_t j = 0; j < Down; ++j)
  {
    for (std::uint32_t i = 0; i < Around; ++i)
    {
      soup.polygons.push_back({ at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j) });
    }
  }
  soup.materials.assign(soup.polygons.size(), Material());
  return soup;
}

/// Allocates blocks of sizes drawn from `seed` and frees some of them, so that what is
/// allocated next lands elsewhere, in another order; the rest are freed by the destructor.
class HeapShuffle
{
public:
  explicit HeapShuffle(std::uint32_t seed)
  {
    std::uint32_t state = seed * 2654435761u + 1;
    auto next = [&state]
    {
      state = state * 1664525u + 1013904223u;
      return state >> 8;
    };
    for (int i = 0; i < 200; ++i)
    {
      this->Blocks.push_back(std::malloc(16 + next() % 20000));
    }
    for (void*& block : this->Blocks)
    {
      if (next() % 3 == 0)
      {
        std::free(block);
        block = nullptr;
      }
    }
  }
  ~HeapShuffle()
  {
    for (void* block : this->Blocks)
    {
      std::free(block);
    }
  }
  HeapShuffle(const HeapShuffle&) = delete;
  HeapShuffle& operator=(const HeapShuffle&) = delete;

private:
  std::vector<void*> Blocks;
};

template <typename T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b)
{
  return a.size() == b.size() &&
    (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

void expectRepeatable(const PolygonSoup& soup, const std::string& scene)
{
  const RemeshResult first = remesh(soup, RemeshOptions());
  ASSERT_GT(first.statistics.contactSplitTriangles, 0u)
    << scene << ": the floor was not split under the box";
  // On the unfixed code 2 (boxes) to 14 (sphere) of these 24 heaps changed the patches. The
  // seeds are fixed: the heaps are the same in every run of the test.
  for (std::uint32_t seed = 1; seed <= 24; ++seed)
  {
    HeapShuffle shuffle(seed);
    const RemeshResult again = remesh(soup, RemeshOptions());
    EXPECT_EQ(again.mesh.triangles.size(), first.mesh.triangles.size())
      << scene << ", heap " << seed;
    EXPECT_TRUE(sameBits(again.mesh.points, first.mesh.points) &&
      sameBits(again.mesh.triangles, first.mesh.triangles) &&
      sameBits(again.mesh.reflectance, first.mesh.reflectance))
      << scene << ", heap " << seed << ": the patches differ";
  }
}
}

TEST(RemeshingRepeatable, BoxOnTheFloorDiagonal)
{
  // The footprint's corners (1, 1) and (1.6, 1.6) lie on the floor's diagonal.
  expectRepeatable(boxOnFloor(1, 1), "box on the diagonal");
}

TEST(RemeshingRepeatable, BoxInsideOneFloorTriangle)
{
  // The whole footprint, a square, in one floor triangle: its four corners are cocircular.
  expectRepeatable(boxOnFloor(-3, 1), "box inside one triangle");
}

TEST(RemeshingRepeatable, SphereThroughTheFloor)
{
  expectRepeatable(sphereThroughFloor(), "sphere through the floor");
}
