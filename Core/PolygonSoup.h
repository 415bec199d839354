// What remeshing takes in: polygons with one material each, as users have them.
#pragma once

#include "Rgb.h"
#include "Vec3.h"

#include <cstdint>
#include <vector>

namespace mlr
{

/// What a surface is made of. One per input polygon; room for more attributes later.
struct Material
{
  Rgb reflectance{ 0.5, 0.5, 0.5 };
  /// Radiant exitance emitted from the front side (W/m^2, RGB); zero for most surfaces.
  Rgb emission{ 0, 0, 0 };

  bool operator==(const Material& o) const
  {
    return this->reflectance == o.reflectance && this->emission == o.emission;
  }
  bool operator!=(const Material& o) const { return !(*this == o); }
};

/// A raw polygonal surface as users have it: any vertex count, possibly concave, slightly
/// non-planar, duplicated, open or non-manifold.
struct PolygonSoup
{
  std::vector<Vec3> points;
  std::vector<std::vector<std::uint32_t>> polygons;
  std::vector<Material> materials; ///< one per polygon
};

} // namespace mlr
