// A town block of box buildings on a ground plane, for the sun benchmark and tests.
#pragma once

#include "OccluderScenes.h"
#include "Scene.h"

#include <string>
#include <vector>

namespace mlr::scenes
{

/// One building: a closed box standing on the ground (no bottom face), normals out.
struct Building
{
  std::string name;
  AxisBox box;
};

/**
 * A Parisian-style town block, z up and north +y, metres: a perimeter block of four wings
 * (heights 15 m south, 24 m north, 18 m west, 21 m east) around a 20 x 20 m courtyard with a
 * 4 m pavilion in it, 2 m alleys between the wings, streets around it and a 12 m row of
 * buildings across the eastern street, on a 64 x 64 m ground [0, 64]^2 at z = 0.
 *
 * Walls and roofs are cut into square cells of about `wallCell` metres, the ground into
 * cells of `groundCell` metres (which must divide 2 m, the grid every footprint lies on);
 * every cell is two patches. Ground cells under a building are left out, so that no patch is
 * closed in. The defaults give about 3,000 patches.
 */
struct TownBlock
{
  PatchMesh mesh;
  std::vector<Building> buildings;
  AxisBox ground; ///< the ground's extent (zero height)
  /// Patches [0, groundPatches) are the ground, facing up.
  std::size_t groundPatches = 0;
  Vec3 north{ 0, 1, 0 }, up{ 0, 0, 1 };
};
TownBlock townBlock(double wallCell = 3.0, double groundCell = 2.0);

} // namespace mlr::scenes
