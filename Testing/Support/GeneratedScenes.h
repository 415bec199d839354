// Procedural scenes for tests and benchmarks: gridded quads, boxes and a paper-scale room.
#pragma once

#include "MovingLight.h"
#include "Remeshing.h"
#include "Scene.h"

#include <vector>

namespace mlr::scenes
{

/// Appends the quad origin + s*u + t*v (s, t in [0,1]) as nu x nv cells of 2 triangles,
/// facing u x v.
void addGriddedQuad(PatchMesh& mesh, const Vec3& origin, const Vec3& u, const Vec3& v, int nu,
  int nv, const Rgb& reflectance);

/// Appends an axis-aligned box [lo, hi], each face cut into cells of about `cell` size,
/// with normals facing out (or in). `faceReflectance` is indexed -x,+x,-y,+y,-z,+z.
void addBox(PatchMesh& mesh, const Vec3& lo, const Vec3& hi, double cell, bool inward,
  const std::vector<Rgb>& faceReflectance, bool skipBottom = false);

/// A closed unit-ish box [0,1]^3 of uniform or per-face reflectance, cells per edge `n`.
PatchMesh closedBox(int n, bool inward, const std::vector<Rgb>& faceReflectance);

/// A horizontal square light of side `side` centred at `centre`, facing down (-z).
std::vector<std::vector<Vec3>> squareLightFacingDown(const Vec3& centre, double side);

/// `count` positions on the segment from `from` to `to`, as translations of a light
/// whose centroid is `centroid`.
std::vector<Vec3> translationsAlong(
  const Vec3& centroid, const Vec3& from, const Vec3& to, std::size_t count);

/**
 * The paper's configuration, generated: a Cornell-like closed room (5.5 m, white with a red
 * and a green wall, inward normals) with a short and a tall block, about 2,700 patches
 * (10,800 elements), and a small ceiling light (1.3 x 1.05 m, facing down) whose 30 positions
 * run along a diagonal just below the ceiling.
 */
struct PaperRoom
{
  PatchMesh mesh;
  std::vector<std::vector<Vec3>> light;
  std::vector<Vec3> translations;
};
PaperRoom paperScaleRoom(std::size_t frames = 30, double cell = 0.385);

// --- Polygon soups, as users give them to remeshing ---------------------------------------

/// Appends a polygon through the given points (new points each time, as exporters do).
void addPolygon(PolygonSoup& soup, const std::vector<Vec3>& corners, const Rgb& rho);

/// The corners of the face of box [lo, hi] on `axis` at its `high` side, counter-clockwise
/// seen from outside (right-hand normal out of the box).
std::vector<Vec3> boxFace(const Vec3& lo, const Vec3& hi, int axis, bool high);

/// A box as 6 quads (faces -x, +x, -y, +y, -z, +z), normals out of the box unless `inward`.
PolygonSoup boxOfQuads(const Vec3& lo, const Vec3& hi, const std::vector<Rgb>& walls,
  bool inward = false, bool skipBottom = false);

void append(PolygonSoup& to, const PolygonSoup& from);

/// A geodesic sphere: the icosahedron's faces cut into frequency^2 triangles each and pushed
/// onto the sphere, 20 frequency^2 triangles sharing their points.
PolygonSoup icosphere(int frequency, double radius = 1.0);

/// The paper-scale room of paperScaleRoom() as 16 big quads, before any remeshing.
PolygonSoup paperRoomOfQuads();

/// Contact lines: a floor [0, floorSize]^2 at z = 0 facing up, given as one quad that passes
/// under a block [blockLo, blockHi] standing on it (blockLo.z = 0), the block a closed box with
/// normals out, or open at its bottom with `openBottom`. Polygons: the floor, then the block's.
PolygonSoup blockOnFloor(double floorSize, const Vec3& blockLo, const Vec3& blockHi,
  const Rgb& floor, const Rgb& block, bool openBottom = false);

/// Contact lines: a wall x = 0, y and z in [0, 1], facing +x, and a panel through it: the quad
/// y = 0.5, x in [-0.3, 0.3], z in [0.2, 0.8] when `thickness` is 0, else a closed box of that
/// thickness around it (normals out). The wall is the first polygon.
PolygonSoup panelThroughWall(double thickness = 0);

/**
 * A large input for remeshing benchmarks, with contact lines and a covered face: a floor
 * [-3, 3]^2 at z = 0 facing up, cut into floorCells^2 squares of 2 triangles sharing their
 * points; an icosphere of `sphereFrequency` (radius 1.5, centre (0, 0, 0.9)) through it; and
 * a closed box 1 x 1 x 1 of 6 quads (normals out) standing on it at (1.2345, 1.4321).
 * 2 floorCells^2 + 20 sphereFrequency^2 + 6 polygons in three materials.
 */
PolygonSoup sphereAndBoxOnTiledFloor(int floorCells, int sphereFrequency);

} // namespace mlr::scenes
