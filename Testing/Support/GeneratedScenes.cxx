#include "GeneratedScenes.h"

#include <cmath>

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
    { lo, ez, ey },            // -x
    { lo + ex, ey, ez },       // +x
    { lo, ex, ez },            // -y
    { lo + ey, ez, ex },       // +y
    { lo, ey, ex },            // -z
    { lo + ez, ex, ey },       // +z
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
      addGriddedQuad(mesh, face.origin, face.v, face.u, cells(length(face.v)), cells(length(face.u)), rho);
    }
    else
    {
      addGriddedQuad(mesh, face.origin, face.u, face.v, cells(length(face.u)), cells(length(face.v)), rho);
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
  room.translations =
    translationsAlong(centre, Vec3(1.9, 1.9, 5.49), Vec3(3.6, 3.6, 5.49), frames);
  return room;
}

} // namespace mlr::scenes
