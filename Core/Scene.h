// The radiosity scene: triangular patches, each split 1:4 into elements.
#pragma once

#include "Reconstruction.h"
#include "Rgb.h"
#include "Vec3.h"

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace mlr
{

/// The side of a surface: Front is the side the right-hand-rule normal points to.
enum class Side : std::uint8_t
{
  Front = 0,
  Back = 1,
};

using Triangle = std::array<std::uint32_t, 3>;

/// The largest coordinate magnitude accepted in scenes, lights and light positions. Embree
/// traces rays in single precision and only accepts ray origins within about +-1.8e18; the
/// offsets that lift rays off surfaces grow with the scene's size.
constexpr double MaximumCoordinate = 1e15;

/// True when every coordinate of p is finite and within +-MaximumCoordinate.
inline bool isWithinCoordinateRange(const Vec3& p)
{
  return std::abs(p.x) <= MaximumCoordinate && std::abs(p.y) <= MaximumCoordinate &&
    std::abs(p.z) <= MaximumCoordinate;
}

/// Throws mlr::Error when any point has a NaN or infinite coordinate (saying how many) or
/// lies beyond +-MaximumCoordinate (saying where).
void checkScenePoints(const std::vector<Vec3>& points);

/// Patches as given by the caller (or by remeshing): one triangle and one reflectance each.
struct PatchMesh
{
  std::vector<Vec3> points;
  std::vector<Triangle> triangles;
  std::vector<Rgb> reflectance; ///< one per triangle, every channel in [0, 1)
  /// Radiant exitance (W/m^2, RGB) emitted from each triangle's front side: one per triangle,
  /// or empty when nothing in the scene emits.
  std::vector<Rgb> emission;
};

/**
 * Patches and elements with their geometry and materials.
 *
 * Patch p owns elements 4p .. 4p+3, made by splitting it at its edge midpoints:
 * three corner triangles and the middle one, all oriented like the patch. Midpoints of
 * edges shared by two patches are shared too, so the element mesh is as connected as the
 * patch mesh. A Scene is immutable and always valid: fromPatchMesh throws mlr::Error
 * naming the first problem it finds.
 */
class Scene
{
public:
  static constexpr std::size_t ElementsPerPatch = 4;

  static Scene fromPatchMesh(const PatchMesh& mesh);

  /// The bytes a scene of these counts holds, and with it the patch mesh it was built from
  /// (which an animation keeps): what the solve's memory check adds to the solve's own.
  static std::uint64_t estimateMemory(
    std::size_t patches, std::size_t elements, std::size_t points, bool emits);
  /// The bytes this scene holds.
  std::uint64_t memoryBytes() const;

  std::size_t patchCount() const { return this->PatchTriangles.size(); }
  std::size_t elementCount() const { return this->ElementTriangles.size(); }
  static std::size_t patchOfElement(std::size_t element) { return element / ElementsPerPatch; }

  /// Patch corners first (same indices as the input), then edge midpoints.
  const std::vector<Vec3>& points() const { return this->Points; }
  const std::vector<Triangle>& patchTriangles() const { return this->PatchTriangles; }
  const std::vector<Triangle>& elementTriangles() const { return this->ElementTriangles; }

  const Vec3& patchNormal(std::size_t p) const { return this->PatchNormals[p]; }
  /// The smooth connected surface patch p belongs to (surfaceRegions in SurfaceRegions.h):
  /// all of a surface's elements and patches show the one side it chooses (Solution).
  std::uint32_t patchRegion(std::size_t p) const { return this->PatchRegions[p]; }
  std::size_t regionCount() const { return this->RegionCount; }
  double patchArea(std::size_t p) const { return this->PatchAreas[p]; }
  const Rgb& patchReflectance(std::size_t p) const { return this->Reflectance[p]; }
  /// How final gathering reads patch p's bounced light as a linear function (Reconstruction.h).
  const LinearStencil& patchStencil(std::size_t p) const { return this->PatchStencils[p]; }

  const Vec3& elementNormal(std::size_t e) const { return this->PatchNormals[patchOfElement(e)]; }
  double elementArea(std::size_t e) const { return this->ElementAreas[e]; }
  const Rgb& elementReflectance(std::size_t e) const
  {
    return this->Reflectance[patchOfElement(e)];
  }

  /// Self-emission (W/m^2, front side only): zero unless the scene's material emits.
  Rgb patchEmission(std::size_t p) const
  {
    return this->Emission.empty() ? Rgb() : this->Emission[p];
  }
  Rgb elementEmission(std::size_t e) const { return this->patchEmission(patchOfElement(e)); }
  /// True when some patch emits light of its own.
  bool hasEmission() const { return !this->Emission.empty(); }

  /// The unit normal on the given side of element e.
  Vec3 elementSideNormal(std::size_t e, Side side) const
  {
    return side == Side::Front ? this->elementNormal(e) : -this->elementNormal(e);
  }

  double totalArea() const { return this->TotalArea; }
  const Vec3& boundsMin() const { return this->BoundsMin; }
  const Vec3& boundsMax() const { return this->BoundsMax; }
  /// Length of the bounding box diagonal: the scale for ray offsets.
  double diagonal() const { return length(this->BoundsMax - this->BoundsMin); }

private:
  std::vector<Vec3> Points;
  std::vector<Triangle> PatchTriangles;
  std::vector<Triangle> ElementTriangles;
  std::vector<Vec3> PatchNormals;
  std::vector<std::uint32_t> PatchRegions;
  std::size_t RegionCount = 0;
  std::vector<double> PatchAreas;
  std::vector<double> ElementAreas;
  std::vector<Rgb> Reflectance;
  std::vector<LinearStencil> PatchStencils;
  std::vector<Rgb> Emission; ///< empty when nothing emits
  double TotalArea = 0;
  Vec3 BoundsMin, BoundsMax;
};

} // namespace mlr
