// Remeshing any polygon soup into well-shaped patches of one material each: geometry and
// materials are kept, fine input is coarsened, and messy input never crashes.
#include "Error.h"
#include "GeneratedScenes.h"
#include "Remeshing.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>

using namespace mlr;

namespace
{
constexpr double Pi = 3.14159265358979323846;

// --- Input surfaces -------------------------------------------------------------------

/// Appends a polygon through the given points (new points each time, as exporters do).
void addPolygon(PolygonSoup& soup, const std::vector<Vec3>& corners, const Rgb& rho)
{
  std::vector<std::uint32_t> polygon;
  for (const Vec3& p : corners)
  {
    polygon.push_back(static_cast<std::uint32_t>(soup.points.size()));
    soup.points.push_back(p);
  }
  soup.polygons.push_back(polygon);
  soup.materials.push_back(Material{ rho });
}

/// The corners of the face of box [lo, hi] on `axis` at its `high` side, counter-clockwise
/// seen from outside (right-hand normal out of the box).
std::vector<Vec3> boxFace(const Vec3& lo, const Vec3& hi, int axis, bool high)
{
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  auto corner = [&](bool su, bool sv) {
    Vec3 p = high ? hi : lo;
    p[u] = su ? hi[u] : lo[u];
    p[v] = sv ? hi[v] : lo[v];
    return p;
  };
  std::vector<Vec3> face = { corner(false, false), corner(true, false), corner(true, true), corner(false, true) };
  if (!high)
  {
    std::reverse(face.begin(), face.end());
  }
  return face;
}

/// A box as 6 quads (faces -x, +x, -y, +y, -z, +z), normals out of the box unless `inward`.
PolygonSoup boxOfQuads(const Vec3& lo, const Vec3& hi, const std::vector<Rgb>& walls,
  bool inward = false, bool skipBottom = false)
{
  PolygonSoup soup;
  for (int f = 0; f < 6; ++f)
  {
    if (skipBottom && f == 4)
    {
      continue;
    }
    std::vector<Vec3> face = boxFace(lo, hi, f / 2, f % 2 == 1);
    if (inward)
    {
      std::reverse(face.begin(), face.end());
    }
    addPolygon(soup, face, walls[static_cast<std::size_t>(f) % walls.size()]);
  }
  return soup;
}

void append(PolygonSoup& to, const PolygonSoup& from)
{
  const auto base = static_cast<std::uint32_t>(to.points.size());
  to.points.insert(to.points.end(), from.points.begin(), from.points.end());
  for (auto polygon : from.polygons)
  {
    for (auto& v : polygon)
    {
      v += base;
    }
    to.polygons.push_back(polygon);
  }
  to.materials.insert(to.materials.end(), from.materials.begin(), from.materials.end());
}

/// A geodesic sphere: the icosahedron's faces cut into frequency^2 triangles each and pushed
/// onto the sphere, 20 frequency^2 triangles sharing their points.
PolygonSoup icosphere(int frequency, double radius = 1.0)
{
  const double t = (1 + std::sqrt(5.0)) / 2;
  const std::vector<Vec3> ico = { { -1, t, 0 }, { 1, t, 0 }, { -1, -t, 0 }, { 1, -t, 0 },
    { 0, -1, t }, { 0, 1, t }, { 0, -1, -t }, { 0, 1, -t }, { t, 0, -1 }, { t, 0, 1 },
    { -t, 0, -1 }, { -t, 0, 1 } };
  const std::vector<std::array<int, 3>> faces = { { 0, 11, 5 }, { 0, 5, 1 }, { 0, 1, 7 },
    { 0, 7, 10 }, { 0, 10, 11 }, { 1, 5, 9 }, { 5, 11, 4 }, { 11, 10, 2 }, { 10, 7, 6 },
    { 7, 1, 8 }, { 3, 9, 4 }, { 3, 4, 2 }, { 3, 2, 6 }, { 3, 6, 8 }, { 3, 8, 9 }, { 4, 9, 5 },
    { 2, 4, 11 }, { 6, 2, 10 }, { 8, 6, 7 }, { 9, 8, 1 } };
  PolygonSoup soup;
  // A point is a weighted sum of icosahedron corners; keyed by its sorted (corner, weight)
  // pairs so that faces sharing an edge share its points exactly.
  std::map<std::vector<std::pair<int, int>>, std::uint32_t> pointOf;
  auto point = [&](std::vector<std::pair<int, int>> weights) {
    weights.erase(std::remove_if(weights.begin(), weights.end(), [](auto w) { return w.second == 0; }),
      weights.end());
    std::sort(weights.begin(), weights.end());
    const auto found = pointOf.find(weights);
    if (found != pointOf.end())
    {
      return found->second;
    }
    Vec3 p;
    for (const auto& [corner, weight] : weights)
    {
      p += ico[static_cast<std::size_t>(corner)] * double(weight);
    }
    const auto index = static_cast<std::uint32_t>(soup.points.size());
    soup.points.push_back(normalize(p) * radius);
    pointOf.emplace(weights, index);
    return index;
  };
  const int n = frequency;
  for (const auto& [a, b, c] : faces)
  {
    auto at = [&](int i, int j) { return point({ { a, n - i - j }, { b, i }, { c, j } }); };
    for (int j = 0; j < n; ++j)
    {
      for (int i = 0; i + j < n; ++i)
      {
        soup.polygons.push_back({ at(i, j), at(i + 1, j), at(i, j + 1) });
        if (i + j + 1 < n)
        {
          soup.polygons.push_back({ at(i + 1, j), at(i + 1, j + 1), at(i, j + 1) });
        }
      }
    }
  }
  soup.materials.assign(soup.polygons.size(), Material{ Rgb(0.5) });
  return soup;
}

// --- Measures ---------------------------------------------------------------------------

double area(const PatchMesh& mesh, std::size_t p)
{
  const Triangle& t = mesh.triangles[p];
  return 0.5 * length(triangleAreaVector(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]]));
}

double totalArea(const PatchMesh& mesh)
{
  double sum = 0;
  for (std::size_t p = 0; p < mesh.triangles.size(); ++p)
  {
    sum += area(mesh, p);
  }
  return sum;
}

Vec3 normal(const PatchMesh& mesh, std::size_t p)
{
  const Triangle& t = mesh.triangles[p];
  return normalize(triangleAreaVector(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]]));
}

double minimumAngleDegrees(const PatchMesh& mesh, std::size_t p)
{
  const Triangle& t = mesh.triangles[p];
  double smallest = 180;
  for (int k = 0; k < 3; ++k)
  {
    const Vec3& a = mesh.points[t[static_cast<std::size_t>(k)]];
    const Vec3 u = normalize(mesh.points[t[static_cast<std::size_t>((k + 1) % 3)]] - a);
    const Vec3 v = normalize(mesh.points[t[static_cast<std::size_t>((k + 2) % 3)]] - a);
    smallest = std::min(smallest, std::acos(std::clamp(dot(u, v), -1.0, 1.0)) * 180 / Pi);
  }
  return smallest;
}

bool contains(const std::vector<std::string>& warnings, const std::string& words)
{
  return std::any_of(warnings.begin(), warnings.end(),
    [&](const std::string& w) { return w.find(words) != std::string::npos; });
}

std::string joined(const std::vector<std::string>& warnings)
{
  std::string all;
  for (const std::string& w : warnings)
  {
    all += "\n  " + w;
  }
  return all.empty() ? " (none)" : all;
}

/// Which face of the box [0,1]^3 a point lies on (-x,+x,-y,+y,-z,+z), or -1 if none or
/// ambiguous (on an edge).
int cubeFaceOf(const Vec3& p, double tolerance = 1e-9)
{
  int face = -1;
  for (int axis = 0; axis < 3; ++axis)
  {
    for (int side = 0; side < 2; ++side)
    {
      if (std::abs(p[axis] - side) <= tolerance)
      {
        if (face >= 0)
        {
          return -1;
        }
        face = 2 * axis + side;
      }
    }
  }
  return face;
}

bool onUnitCube(const Vec3& p, double tolerance = 1e-9)
{
  bool onFace = false;
  for (int axis = 0; axis < 3; ++axis)
  {
    if (p[axis] < -tolerance || p[axis] > 1 + tolerance)
    {
      return false;
    }
    onFace = onFace || std::abs(p[axis]) <= tolerance || std::abs(p[axis] - 1) <= tolerance;
  }
  return onFace;
}

/// The face planes (-x,+x,-y,+y,-z,+z) of the unit cube that hold all three corners of patch p.
std::vector<int> commonCubeFaces(const PatchMesh& mesh, std::size_t p, double tolerance = 1e-9)
{
  std::vector<int> common;
  for (int face = 0; face < 6; ++face)
  {
    const int axis = face / 2;
    const double value = face % 2;
    bool all = true;
    for (std::uint32_t v : mesh.triangles[p])
    {
      all = all && std::abs(mesh.points[v][axis] - value) <= tolerance;
    }
    if (all)
    {
      common.push_back(face);
    }
  }
  return common;
}

template <typename Action>
void expectError(Action action, const std::string& words)
{
  try
  {
    action();
    ADD_FAILURE() << "no error; expected one mentioning \"" << words << "\"";
  }
  catch (const Error& e)
  {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << "message: " << e.what();
  }
}

RemeshOptions withEdgeLength(double h)
{
  RemeshOptions options;
  options.targetEdgeLength = h;
  return options;
}

const std::vector<Rgb> sixWalls = { Rgb(0.6, 0.2, 0.3), Rgb(0.3, 0.6, 0.2), Rgb(0.5, 0.5, 0.5),
  Rgb(0.7, 0.4, 0.6), Rgb(0.4, 0.3, 0.7), Rgb(0.55, 0.65, 0.45) };
}

// --- Geometry and materials --------------------------------------------------------------

TEST(Remeshing, UnitCubeKeepsFacesEdgesAndShape)
{
  const RemeshResult result = remesh(boxOfQuads({ 0, 0, 0 }, { 1, 1, 1 }, { Rgb(0.5) }), withEdgeLength(0.1));
  const PatchMesh& mesh = result.mesh;
  EXPECT_TRUE(result.warnings.empty()) << joined(result.warnings);
  EXPECT_EQ(result.statistics.fallbackRegions, 0u);
  ASSERT_GT(mesh.triangles.size(), 800u);
  EXPECT_LT(mesh.triangles.size(), 2400u);
  for (const Vec3& p : mesh.points)
  {
    EXPECT_TRUE(onUnitCube(p)) << p.x << " " << p.y << " " << p.z;
  }
  EXPECT_NEAR(totalArea(mesh), 6.0, 6.0 * 0.005);
  double smallestAngle = 180;
  for (std::size_t p = 0; p < mesh.triangles.size(); ++p)
  {
    EXPECT_EQ(commonCubeFaces(mesh, p).size(), 1u) << "patch " << p << " crosses a cube edge";
    smallestAngle = std::min(smallestAngle, minimumAngleDegrees(mesh, p));
  }
  EXPECT_GT(smallestAngle, 20.0);
  // The 8 corners are kept, not rounded.
  for (int corner = 0; corner < 8; ++corner)
  {
    const Vec3 c(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
    EXPECT_TRUE(std::find(mesh.points.begin(), mesh.points.end(), c) != mesh.points.end())
      << "corner " << c.x << " " << c.y << " " << c.z;
  }
  const Scene scene = Scene::fromPatchMesh(mesh);
  EXPECT_EQ(scene.elementCount(), 4 * scene.patchCount());
  EXPECT_NEAR(scene.totalArea(), 6.0, 6.0 * 0.005);
}

TEST(Remeshing, EveryElementCarriesTheReflectanceOfItsWall)
{
  const RemeshResult result = remesh(boxOfQuads({ 0, 0, 0 }, { 1, 1, 1 }, sixWalls), withEdgeLength(0.12));
  EXPECT_EQ(result.statistics.fallbackRegions, 0u);
  const Scene scene = Scene::fromPatchMesh(result.mesh);
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    const Triangle& t = scene.elementTriangles()[e];
    const Vec3 centroid = (scene.points()[t[0]] + scene.points()[t[1]] + scene.points()[t[2]]) / 3.0;
    const int face = cubeFaceOf(centroid);
    ASSERT_GE(face, 0) << "element " << e << " is not inside one face of the box";
    EXPECT_EQ(scene.elementReflectance(e), sixWalls[static_cast<std::size_t>(face)]) << "element " << e;
  }
}

TEST(Remeshing, OutputKeepsTheOrientationOfEachInputPolygon)
{
  // Inward walls, except one facing out by mistake: orientation repair must not change
  // what the user gave.
  PolygonSoup soup = boxOfQuads({ 0, 0, 0 }, { 1, 1, 1 }, { Rgb(0.5) }, true);
  std::reverse(soup.polygons[3].begin(), soup.polygons[3].end());
  const RemeshResult result = remesh(soup, withEdgeLength(0.15));
  const PatchMesh& mesh = result.mesh;
  for (std::size_t p = 0; p < mesh.triangles.size(); ++p)
  {
    const std::vector<int> faces = commonCubeFaces(mesh, p);
    ASSERT_EQ(faces.size(), 1u);
    const int axis = faces[0] / 2;
    Vec3 inward;
    inward[axis] = faces[0] % 2 == 0 ? 1 : -1;
    const double expected = faces[0] == 3 ? -1 : 1;
    EXPECT_NEAR(dot(normal(mesh, p), inward), expected, 1e-9) << "patch " << p << " on face " << faces[0];
  }
}

TEST(Remeshing, FineIcosphereCoarsensToAboutTheTargetCount)
{
  const PolygonSoup sphere = icosphere(63); // 79,380 triangles
  ASSERT_EQ(sphere.polygons.size(), 79380u);
  RemeshOptions options;
  options.targetPatchCount = 2000;
  const RemeshResult result = remesh(sphere, options);
  EXPECT_EQ(result.statistics.fallbackRegions, 0u) << joined(result.warnings);
  EXPECT_GE(result.statistics.patches, 1500u);
  EXPECT_LE(result.statistics.patches, 2600u);
  EXPECT_NEAR(result.statistics.outputArea / result.statistics.inputArea, 1.0, 0.01);
  EXPECT_NEAR(totalArea(result.mesh) / result.statistics.inputArea, 1.0, 0.01);
  for (const Vec3& p : result.mesh.points)
  {
    EXPECT_NEAR(length(p), 1.0, 1e-3);
  }
  std::printf("icosphere: %zu -> %zu patches in %.2f s, area ratio %.5f\n",
    sphere.polygons.size(), result.statistics.patches, result.statistics.seconds,
    result.statistics.outputArea / result.statistics.inputArea);
}
