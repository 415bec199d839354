#include "TownScenes.h"

#include "Error.h"
#include "GeneratedScenes.h"

#include <cmath>
#include <cstdint>

namespace mlr::scenes
{

TownBlock townBlock(double wallCell, double groundCell)
{
  const double grid = 2.0; // every footprint corner lies on this grid
  const double perGrid = grid / groundCell;
  if (!(wallCell > 0) || !(groundCell > 0) || std::abs(perGrid - std::round(perGrid)) > 1e-9)
  {
    throw Error("townBlock: the wall cell must be positive and the ground cell must divide 2 m");
  }
  TownBlock town;
  town.ground = { Vec3(0, 0, 0), Vec3(64, 64, 0) };
  town.buildings = {
    { "south wing", { Vec3(12, 12, 0), Vec3(52, 22, 15) } },
    { "north wing", { Vec3(12, 42, 0), Vec3(52, 52, 24) } },
    { "west wing", { Vec3(12, 24, 0), Vec3(22, 40, 18) } },
    { "east wing", { Vec3(42, 24, 0), Vec3(52, 40, 21) } },
    { "pavilion", { Vec3(28, 28, 0), Vec3(36, 34, 4) } },
    { "east row", { Vec3(58, 6, 0), Vec3(64, 58, 12) } },
  };
  const Rgb paving(0.25, 0.24, 0.22), limestone(0.62, 0.57, 0.47), zinc(0.35, 0.37, 0.4),
    brick(0.45, 0.25, 0.18), pavilionGlass(0.25, 0.35, 0.3);

  // The ground first, cell by cell, skipping cells under a building; cells share their
  // corners, so the ground is one connected surface.
  const int n = static_cast<int>(std::lround((town.ground.hi.x - town.ground.lo.x) / groundCell));
  std::vector<std::int64_t> pointIndex(static_cast<std::size_t>((n + 1) * (n + 1)), -1);
  auto point = [&](int i, int j)
  {
    std::int64_t& index = pointIndex[static_cast<std::size_t>(j * (n + 1) + i)];
    if (index < 0)
    {
      index = static_cast<std::int64_t>(town.mesh.points.size());
      town.mesh.points.push_back(town.ground.lo + Vec3(i * groundCell, j * groundCell, 0));
    }
    return static_cast<std::uint32_t>(index);
  };
  for (int j = 0; j < n; ++j)
  {
    for (int i = 0; i < n; ++i)
    {
      const Vec3 centre = town.ground.lo + Vec3((i + 0.5) * groundCell, (j + 0.5) * groundCell, 0);
      bool covered = false;
      for (const Building& b : town.buildings)
      {
        covered = covered ||
          (centre.x > b.box.lo.x && centre.x < b.box.hi.x && centre.y > b.box.lo.y &&
            centre.y < b.box.hi.y);
      }
      if (covered)
      {
        continue;
      }
      // Counter-clockwise seen from above: facing up.
      const std::uint32_t a = point(i, j), b = point(i + 1, j), c = point(i + 1, j + 1),
                          d = point(i, j + 1);
      town.mesh.triangles.push_back({ a, b, c });
      town.mesh.triangles.push_back({ a, c, d });
      town.mesh.reflectance.push_back(paving);
      town.mesh.reflectance.push_back(paving);
    }
  }
  town.groundPatches = town.mesh.triangles.size();

  for (const Building& b : town.buildings)
  {
    const bool brickRow = b.name == "east row";
    const Rgb walls = b.name == "pavilion" ? pavilionGlass : brickRow ? brick : limestone;
    // Faces -x, +x, -y, +y, -z (left out), +z: roofs of zinc.
    addBox(town.mesh, b.box.lo, b.box.hi, wallCell, false,
      { walls, walls, walls, walls, walls, zinc }, true);
  }
  return town;
}

} // namespace mlr::scenes
