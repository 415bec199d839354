#include "OccluderScenes.h"

#include "Error.h"
#include "GeneratedScenes.h"

#include <cmath>

namespace mlr::scenes
{

namespace
{
const char* const FaceNames[6] = { "-x", "+x", "-y", "+y", "-z", "+z" };

/// Groups the patches addBox appended from `first` on by the face of `box` they lie on (it
/// appends one face after the other), named `prefix` + the face.
void groupBoxFaces(
  OccludedRoom& room, const std::string& prefix, const AxisBox& box, std::size_t first)
{
  const auto& points = room.mesh.points;
  for (std::size_t p = first; p < room.mesh.triangles.size(); ++p)
  {
    const auto& t = room.mesh.triangles[p];
    const Vec3 a = points[t[0]], b = points[t[1]], c = points[t[2]];
    const Vec3 n = cross(b - a, c - a);
    const Vec3 centroid = (a + b + c) / 3.0;
    int axis = 0;
    for (int i = 1; i < 3; ++i)
    {
      if (std::abs(n[i]) > std::abs(n[axis]))
      {
        axis = i;
      }
    }
    const bool high =
      std::abs(centroid[axis] - box.hi[axis]) < std::abs(centroid[axis] - box.lo[axis]);
    const std::string name = prefix + FaceNames[2 * axis + (high ? 1 : 0)];
    if (room.faces.empty() || room.faces.back().name != name)
    {
      room.faces.push_back(FaceGroup{ name, p, 0, Side::Front });
    }
    ++room.faces.back().patchCount;
  }
}
}

const FaceGroup& OccludedRoom::face(const std::string& name) const
{
  for (const FaceGroup& f : this->faces)
  {
    if (f.name == name)
    {
      return f;
    }
  }
  throw Error("the occluded room has no face named " + name);
}

OccludedRoom occludedRoom(std::size_t positions, const Vec3& shift, double cell)
{
  OccludedRoom room;
  room.room = { shift + Vec3(0, 0, 0), shift + Vec3(4, 4, 2.5) };
  room.block = { shift + Vec3(1, 1, 0), shift + Vec3(2, 2, 1) };
  room.panel = { shift + Vec3(2, 2.75, 0.75), shift + Vec3(3.5, 2.75, 1.75) };

  // Walls -x, +x, -y, +y, floor, ceiling: every face and channel different.
  addBox(room.mesh, room.room.lo, room.room.hi, cell, true,
    { Rgb(0.7, 0.3, 0.3), Rgb(0.3, 0.7, 0.3), Rgb(0.6, 0.6, 0.6), Rgb(0.5, 0.5, 0.7),
      Rgb(0.6, 0.5, 0.4), Rgb(0.8, 0.8, 0.75) });
  groupBoxFaces(room, "room ", room.room, 0);

  std::size_t first = room.mesh.triangles.size();
  addBox(room.mesh, room.block.lo, room.block.hi, cell, false, { Rgb(0.5, 0.6, 0.7) }, true);
  groupBoxFaces(room, "block ", room.block, first);

  // The panel faces -y (u x v = x x z).
  first = room.mesh.triangles.size();
  const Vec3 size = room.panel.hi - room.panel.lo;
  addGriddedQuad(room.mesh, room.panel.lo, Vec3(size.x, 0, 0), Vec3(0, 0, size.z),
    int(std::lround(size.x / cell)), int(std::lround(size.z / cell)), Rgb(0.7, 0.6, 0.5));
  const std::size_t panelPatches = room.mesh.triangles.size() - first;
  room.faces.push_back(FaceGroup{ "panel -y side", first, panelPatches, Side::Front });
  room.faces.push_back(FaceGroup{ "panel +y side", first, panelPatches, Side::Back });

  const FaceGroup& floor = room.face("room -z");
  for (std::size_t p = floor.firstPatch; p < floor.firstPatch + floor.patchCount; ++p)
  {
    const auto& t = room.mesh.triangles[p];
    const Vec3 centroid =
      (room.mesh.points[t[0]] + room.mesh.points[t[1]] + room.mesh.points[t[2]]) / 3.0;
    if (centroid.x > room.block.lo.x && centroid.x < room.block.hi.x &&
      centroid.y > room.block.lo.y && centroid.y < room.block.hi.y)
    {
      room.patchesUnderBlock.push_back(p);
    }
  }

  const Vec3 centre = shift + Vec3(2, 2, 2.4);
  room.light = squareLightFacingDown(centre, 0.5);
  room.power = Rgb(40, 50, 60);
  room.translations =
    translationsAlong(centre, shift + Vec3(1.0, 1.2, 2.4), shift + Vec3(3.0, 3.2, 2.4), positions);
  return room;
}

} // namespace mlr::scenes
