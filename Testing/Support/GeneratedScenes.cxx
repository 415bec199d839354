#include "GeneratedScenes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

namespace mlr::scenes
{

void addGriddedQuad(PatchMesh& mesh, const Vec3& origin, const Vec3& u, const Vec3& v, int nu,
  int nv, const Rgb& reflectance)
{
  const auto base = static_cast<std::uint32_t>(mesh.points.size());
  for (int j = 0; j <= nv; ++j)
  {
    for (int i = 0; i <= nu; ++i)
    {
      mesh.points.push_back(origin + u * (double(i) / nu) + v * (double(j) / nv));
    }
  }
  auto at = [&](int i, int j) { return base + static_cast<std::uint32_t>(j * (nu + 1) + i); };
  for (int j = 0; j < nv; ++j)
  {
    for (int i = 0; i < nu; ++i)
    {
      mesh.triangles.push_back({ at(i, j), at(i + 1, j), at(i + 1, j + 1) });
      mesh.triangles.push_back({ at(i, j), at(i + 1, j + 1), at(i, j + 1) });
      mesh.reflectance.push_back(reflectance);
      mesh.reflectance.push_back(reflectance);
    }
  }
}

void addBox(PatchMesh& mesh, const Vec3& lo, const Vec3& hi, double cell, bool inward,
  const std::vector<Rgb>& faceReflectance, bool skipBottom)
{
  const Vec3 size = hi - lo;
  auto cells = [cell](double length) { return std::max(1, int(std::lround(length / cell))); };
  const Vec3 ex(size.x, 0, 0), ey(0, size.y, 0), ez(0, 0, size.z);
  struct Face
  {
    Vec3 origin, u, v; // u x v points out of the box
  };
  const Face faces[6] = {
    { lo, ez, ey },      // -x
    { lo + ex, ey, ez }, // +x
    { lo, ex, ez },      // -y
    { lo + ey, ez, ex }, // +y
    { lo, ey, ex },      // -z
    { lo + ez, ex, ey }, // +z
  };
  for (int f = 0; f < 6; ++f)
  {
    if (skipBottom && f == 4)
    {
      continue;
    }
    const Face& face = faces[f];
    const Rgb& rho = faceReflectance[static_cast<std::size_t>(f) % faceReflectance.size()];
    if (inward)
    {
      addGriddedQuad(
        mesh, face.origin, face.v, face.u, cells(length(face.v)), cells(length(face.u)), rho);
    }
    else
    {
      addGriddedQuad(
        mesh, face.origin, face.u, face.v, cells(length(face.u)), cells(length(face.v)), rho);
    }
  }
}

PatchMesh closedBox(int n, bool inward, const std::vector<Rgb>& faceReflectance)
{
  PatchMesh mesh;
  addBox(mesh, Vec3(0, 0, 0), Vec3(1, 1, 1), 1.0 / n, inward, faceReflectance);
  return mesh;
}

std::vector<std::vector<Vec3>> squareLightFacingDown(const Vec3& c, double side)
{
  const double h = side / 2;
  // Clockwise seen from above, so the right-hand-rule normal points down.
  return { { c + Vec3(-h, -h, 0), c + Vec3(-h, h, 0), c + Vec3(h, h, 0), c + Vec3(h, -h, 0) } };
}

std::vector<Vec3> translationsAlong(
  const Vec3& centroid, const Vec3& from, const Vec3& to, std::size_t count)
{
  std::vector<Vec3> t;
  for (std::size_t k = 0; k < count; ++k)
  {
    const double s = count > 1 ? double(k) / double(count - 1) : 0.0;
    t.push_back(from + (to - from) * s - centroid);
  }
  return t;
}

PaperRoom paperScaleRoom(std::size_t frames, double cell)
{
  PaperRoom room;
  const Rgb white(0.75, 0.75, 0.75), red(0.63, 0.065, 0.05), green(0.14, 0.45, 0.091);
  // Faces -x, +x, -y, +y, -z (floor), +z (ceiling); z is up.
  addBox(room.mesh, Vec3(0, 0, 0), Vec3(5.5, 5.5, 5.5), cell, true,
    { red, green, white, white, white, white });
  addBox(room.mesh, Vec3(1.3, 0.65, 0), Vec3(2.95, 2.3, 1.65), cell, false, { white }, true);
  addBox(room.mesh, Vec3(2.65, 2.95, 0), Vec3(4.3, 4.6, 3.3), cell, false, { white }, true);
  const Vec3 centre(2.75, 2.75, 5.49);
  room.light = squareLightFacingDown(centre, 1.15);
  room.translations = translationsAlong(centre, Vec3(1.9, 1.9, 5.49), Vec3(3.6, 3.6, 5.49), frames);
  return room;
}

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

std::vector<Vec3> boxFace(const Vec3& lo, const Vec3& hi, int axis, bool high)
{
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  auto corner = [&](bool su, bool sv)
  {
    Vec3 p = high ? hi : lo;
    p[u] = su ? hi[u] : lo[u];
    p[v] = sv ? hi[v] : lo[v];
    return p;
  };
  std::vector<Vec3> face = { corner(false, false), corner(true, false), corner(true, true),
    corner(false, true) };
  if (!high)
  {
    std::reverse(face.begin(), face.end());
  }
  return face;
}

PolygonSoup boxOfQuads(
  const Vec3& lo, const Vec3& hi, const std::vector<Rgb>& walls, bool inward, bool skipBottom)
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

PolygonSoup icosphere(int frequency, double radius)
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
  auto point = [&](std::vector<std::pair<int, int>> weights)
  {
    weights.erase(
      std::remove_if(weights.begin(), weights.end(), [](auto w) { return w.second == 0; }),
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
  for (const auto& face : faces)
  {
    // Named corners, not a structured binding: lambdas capture bindings only from C++20 on
    // (clang refuses, and the sanitizer and fuzz builds use clang).
    const int a = face[0], b = face[1], c = face[2];
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

PolygonSoup paperRoomOfQuads()
{
  const Rgb white(0.75, 0.75, 0.75), red(0.63, 0.065, 0.05), green(0.14, 0.45, 0.091);
  PolygonSoup room =
    boxOfQuads({ 0, 0, 0 }, { 5.5, 5.5, 5.5 }, { red, green, white, white, white, white }, true);
  append(room, boxOfQuads({ 1.3, 0.65, 0 }, { 2.95, 2.3, 1.65 }, { white }, false, true));
  append(room, boxOfQuads({ 2.65, 2.95, 0 }, { 4.3, 4.6, 3.3 }, { white }, false, true));
  return room;
}

PolygonSoup blockOnFloor(double floorSize, const Vec3& blockLo, const Vec3& blockHi,
  const Rgb& floor, const Rgb& block, bool openBottom)
{
  PolygonSoup soup;
  addPolygon(soup,
    { { 0, 0, 0 }, { floorSize, 0, 0 }, { floorSize, floorSize, 0 }, { 0, floorSize, 0 } }, floor);
  append(soup, boxOfQuads(blockLo, blockHi, { block }, false, openBottom));
  return soup;
}

PolygonSoup panelThroughWall(double thickness)
{
  PolygonSoup soup;
  addPolygon(soup, { { 0, 0, 0 }, { 0, 1, 0 }, { 0, 1, 1 }, { 0, 0, 1 } }, Rgb(0.5));
  if (thickness > 0)
  {
    append(soup,
      boxOfQuads(
        { -0.3, 0.5 - thickness / 2, 0.2 }, { 0.3, 0.5 + thickness / 2, 0.8 }, { Rgb(0.3) }));
  }
  else
  {
    addPolygon(soup,
      { { -0.3, 0.5, 0.2 }, { 0.3, 0.5, 0.2 }, { 0.3, 0.5, 0.8 }, { -0.3, 0.5, 0.8 } }, Rgb(0.3));
  }
  return soup;
}

PolygonSoup sphereAndBoxOnTiledFloor(int floorCells, int sphereFrequency)
{
  PolygonSoup soup;
  const auto n = static_cast<std::uint32_t>(floorCells);
  for (std::uint32_t j = 0; j <= n; ++j)
  {
    for (std::uint32_t i = 0; i <= n; ++i)
    {
      soup.points.push_back({ -3 + 6.0 * i / n, -3 + 6.0 * j / n, 0 });
    }
  }
  auto point = [n](std::uint32_t i, std::uint32_t j) { return j * (n + 1) + i; };
  for (std::uint32_t j = 0; j < n; ++j)
  {
    for (std::uint32_t i = 0; i < n; ++i)
    {
      soup.polygons.push_back({ point(i, j), point(i + 1, j), point(i + 1, j + 1) });
      soup.polygons.push_back({ point(i, j), point(i + 1, j + 1), point(i, j + 1) });
    }
  }
  soup.materials.assign(soup.polygons.size(), Material{ Rgb(0.6) });
  PolygonSoup sphere = icosphere(sphereFrequency, 1.5);
  for (Vec3& p : sphere.points)
  {
    p.z += 0.9;
  }
  sphere.materials.assign(sphere.materials.size(), Material{ Rgb(0.7, 0.3, 0.3) });
  append(soup, sphere);
  append(soup, boxOfQuads({ 1.2345, 1.4321, 0 }, { 2.2345, 2.4321, 1 }, { Rgb(0.3, 0.3, 0.7) }));
  return soup;
}

} // namespace mlr::scenes
