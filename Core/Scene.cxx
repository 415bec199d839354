#include "Scene.h"

#include "Error.h"
#include "MemoryBudget.h"
#include "SurfaceRegions.h"

#include <algorithm>
#include <limits>
#include <sstream>
#include <type_traits>
#include <unordered_map>

namespace mlr
{

namespace
{
std::string describe(const Rgb& c)
{
  std::ostringstream s;
  s << "(" << c.r << ", " << c.g << ", " << c.b << ")";
  return s.str();
}
}

void checkScenePoints(const std::vector<Vec3>& points)
{
  std::size_t nonFinite = 0;
  for (const Vec3& p : points)
  {
    nonFinite += isFinite(p) ? 0 : 1;
  }
  if (nonFinite > 0)
  {
    throw Error("the scene has " + std::to_string(nonFinite) +
      (nonFinite == 1 ? " point" : " points") +
      " with NaN or infinite coordinates: remove or fix them");
  }
  for (const Vec3& p : points)
  {
    if (!isWithinCoordinateRange(p))
    {
      std::ostringstream s;
      s << "the scene has a point at (" << p.x << ", " << p.y << ", " << p.z
        << "): coordinates must stay within +-" << MaximumCoordinate
        << " (rays are traced in single precision); scale the scene down";
      throw Error(s.str());
    }
  }
}

std::uint64_t Scene::estimateMemory(
  std::size_t patches, std::size_t elements, std::size_t points, bool emits)
{
  const std::uint64_t emission = emits ? sizeof(Rgb) : 0;
  const std::uint64_t perPatch = sizeof(Triangle) + sizeof(Vec3) + sizeof(std::uint32_t) +
    sizeof(double) + sizeof(Rgb) + sizeof(LinearStencil) + emission;
  const std::uint64_t perElement = sizeof(Triangle) + sizeof(double);
  // The patch mesh: its corners (fewer than the scene's points), triangles and materials.
  const std::uint64_t mesh = sizeof(Triangle) + sizeof(Rgb) + emission;
  return saturatingSum(saturatingSum(saturatingProduct(patches, perPatch + mesh),
                         saturatingProduct(elements, perElement)),
    saturatingProduct({ points, 2, sizeof(Vec3) }));
}

std::uint64_t Scene::memoryBytes() const
{
  auto bytes = [](const auto& v) -> std::uint64_t
  { return v.capacity() * sizeof(typename std::decay_t<decltype(v)>::value_type); };
  return bytes(this->Points) + bytes(this->PatchTriangles) + bytes(this->ElementTriangles) +
    bytes(this->PatchNormals) + bytes(this->PatchRegions) + bytes(this->PatchAreas) +
    bytes(this->ElementAreas) + bytes(this->Reflectance) + bytes(this->PatchStencils) +
    bytes(this->Emission);
}

Scene Scene::fromPatchMesh(const PatchMesh& mesh)
{
  if (mesh.triangles.empty())
  {
    throw Error("the scene is empty: it has no patches (give at least one triangle)");
  }
  if (mesh.reflectance.size() != mesh.triangles.size())
  {
    std::ostringstream s;
    s << "the scene has " << mesh.triangles.size() << " patches but " << mesh.reflectance.size()
      << " reflectances: give exactly one reflectance per patch";
    throw Error(s.str());
  }
  if (!mesh.emission.empty() && mesh.emission.size() != mesh.triangles.size())
  {
    std::ostringstream s;
    s << "the scene has " << mesh.triangles.size() << " patches but " << mesh.emission.size()
      << " emissions: give one emission per patch, or none";
    throw Error(s.str());
  }
  if (mesh.points.size() >= std::numeric_limits<std::uint32_t>::max() / 2 ||
    mesh.triangles.size() >= (std::size_t(1) << 28))
  {
    throw Error("the scene is too large: it must have fewer than 2^28 patches and 2^31 points");
  }
  checkScenePoints(mesh.points);

  Scene scene;
  scene.Points = mesh.points;
  scene.PatchTriangles = mesh.triangles;
  scene.Reflectance = mesh.reflectance;
  bool emits = false;
  for (std::size_t p = 0; p < mesh.emission.size(); ++p)
  {
    const Rgb& e = mesh.emission[p];
    if (!e.isFinite() || e.minComponent() < 0)
    {
      throw Error("patch " + std::to_string(p) + " has emission " + describe(e) +
        " W/m^2: every channel must be finite and >= 0");
    }
    emits = emits || e.maxComponent() > 0;
  }
  if (emits)
  {
    scene.Emission = mesh.emission; // kept only when something emits
  }
  const std::size_t patches = mesh.triangles.size();
  scene.PatchNormals.resize(patches);
  scene.PatchAreas.resize(patches);

  scene.BoundsMin = Vec3(std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
    std::numeric_limits<double>::max());
  scene.BoundsMax = -scene.BoundsMin;
  for (std::size_t p = 0; p < patches; ++p)
  {
    const Triangle& t = mesh.triangles[p];
    for (std::uint32_t v : t)
    {
      if (v >= mesh.points.size())
      {
        std::ostringstream s;
        s << "patch " << p << " uses point " << v << " but the scene has only "
          << mesh.points.size() << " points";
        throw Error(s.str());
      }
      const Vec3& q = mesh.points[v];
      for (int i = 0; i < 3; ++i)
      {
        scene.BoundsMin[i] = std::min(scene.BoundsMin[i], q[i]);
        scene.BoundsMax[i] = std::max(scene.BoundsMax[i], q[i]);
      }
    }
    const Rgb& rho = mesh.reflectance[p];
    for (int c = 0; c < 3; ++c)
    {
      if (!(rho[c] >= 0.0 && rho[c] < 1.0))
      {
        throw Error("patch " + std::to_string(p) + " has reflectance " + describe(rho) +
          ": every channel must be >= 0 and < 1 (a reflectance of 1 never absorbs, so the "
          "random walk would not end)");
      }
    }
    const Vec3 areaVector =
      triangleAreaVector(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]]);
    const double twiceArea = length(areaVector);
    if (!(twiceArea > 0.0) || !std::isfinite(twiceArea))
    {
      throw Error("patch " + std::to_string(p) +
        " is degenerate (zero area): remove zero-area triangles from the scene");
    }
    scene.PatchNormals[p] = areaVector / twiceArea;
    scene.PatchAreas[p] = 0.5 * twiceArea;
    scene.TotalArea += scene.PatchAreas[p];
  }

  // Split 1:4 at edge midpoints, sharing a midpoint between the patches of an edge.
  std::unordered_map<std::uint64_t, std::uint32_t> midpointOfEdge;
  midpointOfEdge.reserve(patches * 2);
  auto midpoint = [&](std::uint32_t a, std::uint32_t b)
  {
    const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
    auto found = midpointOfEdge.find(key);
    if (found != midpointOfEdge.end())
    {
      return found->second;
    }
    const auto index = static_cast<std::uint32_t>(scene.Points.size());
    scene.Points.push_back((scene.Points[a] + scene.Points[b]) * 0.5);
    midpointOfEdge.emplace(key, index);
    return index;
  };
  scene.ElementTriangles.reserve(patches * ElementsPerPatch);
  scene.ElementAreas.reserve(patches * ElementsPerPatch);
  for (std::size_t p = 0; p < patches; ++p)
  {
    const auto [a, b, c] = mesh.triangles[p];
    const std::uint32_t ab = midpoint(a, b);
    const std::uint32_t bc = midpoint(b, c);
    const std::uint32_t ca = midpoint(c, a);
    for (const Triangle& e : { Triangle{ a, ab, ca }, Triangle{ ab, b, bc }, Triangle{ ca, bc, c },
           Triangle{ ab, bc, ca } })
    {
      scene.ElementTriangles.push_back(e);
      scene.ElementAreas.push_back(0.5 *
        length(triangleAreaVector(scene.Points[e[0]], scene.Points[e[1]], scene.Points[e[2]])));
    }
  }
  scene.PatchRegions = surfaceRegions(scene.PatchTriangles, scene.PatchNormals);
  scene.RegionCount =
    std::size_t(*std::max_element(scene.PatchRegions.begin(), scene.PatchRegions.end())) + 1;
  scene.PatchStencils =
    linearStencils(scene.Points, scene.PatchTriangles, scene.PatchNormals, scene.Reflectance);
  return scene;
}

} // namespace mlr
