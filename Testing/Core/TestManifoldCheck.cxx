// The remesher's own test of whether a triangle soup is a polygon mesh must give CGAL 5.5's
// verdict (is_polygon_soup_a_polygon_mesh()) on every input: the remesher orients and splits
// exactly the soups CGAL's check refused, so any difference would change its patches.
#include "CancellationPoll.h"
#include "ManifoldCheck.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <vector>

using mlr::detail::SoupTriangle;

namespace
{

using Soup = std::vector<SoupTriangle>;

bool ours(const Soup& soup)
{
  mlr::detail::CancellationPoll neverCancelled{ std::function<bool()>() };
  return mlr::detail::isTriangleSoupAPolygonMesh(soup, neverCancelled);
}

bool cgal(const Soup& soup)
{
  return mlr::detail::cgalIsPolygonSoupAPolygonMesh(soup);
}

/// The 12 triangles of a closed box on corners 0-7 (bit 0: x, bit 1: y, bit 2: z), all
/// facing out.
Soup closedBox()
{
  return {
    { 0, 2, 3 }, { 0, 3, 1 }, // z = 0
    { 4, 5, 7 }, { 4, 7, 6 }, // z = 1
    { 0, 1, 5 }, { 0, 5, 4 }, // y = 0
    { 2, 6, 7 }, { 2, 7, 3 }, // y = 1
    { 0, 4, 6 }, { 0, 6, 2 }, // x = 0
    { 1, 3, 7 }, { 1, 7, 5 }, // x = 1
  };
}

/// A closed tetrahedron on the given corners, facing out when they are ordered like 0-3 of
/// the unit tetrahedron (apex last).
void addTetrahedron(Soup& soup, std::size_t a, std::size_t b, std::size_t c, std::size_t apex)
{
  soup.push_back({ a, c, b });
  soup.push_back({ a, b, apex });
  soup.push_back({ b, c, apex });
  soup.push_back({ c, a, apex });
}

void expectSameVerdict(const Soup& soup, bool expected, const char* what)
{
  EXPECT_EQ(cgal(soup), expected) << what << " (CGAL's verdict)";
  EXPECT_EQ(ours(soup), expected) << what << " (ours)";
}

} // namespace

TEST(ManifoldCheck, SameVerdictsAsCgalOnTrickySoups)
{
  expectSameVerdict({}, true, "no triangles");
  expectSameVerdict({ { 0, 1, 2 } }, true, "one triangle");
  expectSameVerdict({ { 5, 9, 7 } }, true, "one triangle, unused indices below");
  expectSameVerdict(closedBox(), true, "a clean closed box");
  expectSameVerdict({ { 0, 1, 2 }, { 0, 2, 3 }, { 0, 3, 4 }, { 0, 4, 1 } }, true,
    "an open fan closed around its centre (a pyramid without a base)");
  expectSameVerdict({ { 0, 1, 2 }, { 0, 2, 3 }, { 0, 3, 4 } }, true, "an open fan, a chain");

  Soup flipped = closedBox();
  std::swap(flipped[5][1], flipped[5][2]);
  expectSameVerdict(flipped, false, "a box with one triangle the wrong way round");
  expectSameVerdict({ { 0, 1, 2 }, { 0, 1, 3 } }, false, "two triangles, same oriented edge");

  expectSameVerdict(
    { { 0, 1, 2 }, { 1, 0, 3 }, { 0, 4, 1 } }, false, "an edge shared by 3 triangles");
  expectSameVerdict({ { 0, 1, 2 }, { 1, 0, 3 }, { 0, 1, 4 }, { 1, 0, 5 } }, false,
    "an edge shared by 4 triangles, two each way");

  Soup cones;
  addTetrahedron(cones, 0, 1, 2, 3);
  addTetrahedron(cones, 4, 5, 6, 3);
  expectSameVerdict(cones, false, "two closed cones touching at their tips");
  expectSameVerdict({ { 0, 1, 2 }, { 0, 3, 4 } }, false, "two triangles touching at a corner");
  Soup coneAndFlap;
  addTetrahedron(coneAndFlap, 0, 1, 2, 3);
  coneAndFlap.push_back({ 3, 4, 5 });
  expectSameVerdict(coneAndFlap, false, "a closed cone and a flap at its tip: a cycle and a chain");
  expectSameVerdict({ { 0, 1, 2 }, { 0, 2, 3 }, { 0, 4, 5 }, { 0, 5, 6 } }, false,
    "two open fans around one vertex, two chains");
  Soup oneCone;
  addTetrahedron(oneCone, 0, 1, 2, 3);
  expectSameVerdict(oneCone, true, "one closed cone");

  expectSameVerdict({ { 0, 0, 1 } }, false, "a triangle with a repeated corner");
  expectSameVerdict({ { 0, 1, 0 } }, false, "a triangle with a repeated corner, first and last");
  Soup boxAndDegenerate = closedBox();
  boxAndDegenerate.push_back({ 3, 7, 3 });
  expectSameVerdict(boxAndDegenerate, false, "a closed box and a degenerate triangle");
  expectSameVerdict({ { 2, 2, 2 } }, false, "a triangle on one point");
}

/// Every soup of one to six triangles drawn with a fixed generator from 6 points: small
/// enough that repeated edges, corners and pinched fans are frequent, a fixed set of cases.
TEST(ManifoldCheck, SameVerdictsAsCgalOnSmallDrawnSoups)
{
  std::uint64_t state = 0x9e3779b97f4a7c15ULL;
  auto draw = [&state](std::size_t n)
  {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<std::size_t>((state >> 33) % n);
  };
  std::size_t accepted = 0;
  for (int i = 0; i < 4000; ++i)
  {
    Soup soup(1 + draw(6));
    const bool allowRepeats = draw(8) == 0;
    for (SoupTriangle& t : soup)
    {
      do
      {
        t = { draw(6), draw(6), draw(6) };
      } while (!allowRepeats && (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]));
    }
    const bool expected = cgal(soup);
    accepted += expected ? 1 : 0;
    ASSERT_EQ(ours(soup), expected) << "drawn soup " << i;
  }
  // Both verdicts are exercised.
  EXPECT_GT(accepted, 100u);
  EXPECT_LT(accepted, 3900u);
}

/// Meshes the remesher really sees pass: the box split into a grid of strips, and the same
/// with every triangle reversed (still a consistently oriented mesh).
TEST(ManifoldCheck, SameVerdictsAsCgalOnAGrid)
{
  constexpr std::size_t N = 30;
  Soup grid;
  for (std::size_t j = 0; j < N; ++j)
  {
    for (std::size_t i = 0; i < N; ++i)
    {
      const std::size_t a = j * (N + 1) + i, b = a + 1, c = a + N + 1, d = c + 1;
      grid.push_back({ a, b, d });
      grid.push_back({ a, d, c });
    }
  }
  expectSameVerdict(grid, true, "a grid");
  Soup reversed = grid;
  for (SoupTriangle& t : reversed)
  {
    std::swap(t[1], t[2]);
  }
  expectSameVerdict(reversed, true, "a reversed grid");
  Soup pinched = grid;
  // A triangle from a corner of the grid to two new points: a second fan at that corner.
  pinched.push_back({ 0, (N + 1) * (N + 1), (N + 1) * (N + 1) + 1 });
  expectSameVerdict(pinched, false, "a grid with a flap at a corner");
  Soup mixed = grid;
  std::swap(mixed[N * N][1], mixed[N * N][2]);
  expectSameVerdict(mixed, false, "a grid with one triangle reversed");
}
