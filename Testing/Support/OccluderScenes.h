// A room with occluders, for the occluder tests: a block standing on the floor and a
// hanging two-sided panel, every surface grouped into named faces.
#pragma once

#include "Scene.h"

#include <cstddef>
#include <string>
#include <vector>

namespace mlr::scenes
{

/// An axis-aligned box [lo, hi]; a panel is a box of zero thickness.
struct AxisBox
{
  Vec3 lo, hi;
};

/// Patches [firstPatch, firstPatch + patchCount) seen from `side`: one face of the scene.
struct FaceGroup
{
  std::string name;
  std::size_t firstPatch = 0;
  std::size_t patchCount = 0;
  Side side = Side::Front;
};

/**
 * A closed 4 x 4 x 2.5 m room (inward normals, square cells of `cell` metres cut into two
 * patches, a different reflectance on every face) with a 1 m block standing on the floor (open at
 * its bottom, aligned with the floor's patches so that no floor patch straddles its footprint) and
 * a 1.5 x 1 m panel hanging at y = 2.75, seen from both sides. A 0.5 m square light facing down
 * moves along a diagonal under the ceiling, over the block and across the panel's plane.
 * Everything, light included, is moved by `shift`.
 */
struct OccludedRoom
{
  PatchMesh mesh;
  std::vector<std::vector<Vec3>> light;
  Rgb power;
  std::vector<Vec3> translations;
  AxisBox room, block, panel;
  /// The room's six faces (front sides), the block's five (front sides, facing out) and
  /// the panel's two sides.
  std::vector<FaceGroup> faces;
  /// The floor's patches under the block: closed in, no light reaches them.
  std::vector<std::size_t> patchesUnderBlock;

  const FaceGroup& face(const std::string& name) const;
};

/// `cell` must divide 0.25 m, so that patches align with the block and the panel.
OccludedRoom occludedRoom(
  std::size_t positions = 4, const Vec3& shift = Vec3(0, 0, 0), double cell = 0.25);

} // namespace mlr::scenes
