// The smooth connected surfaces of a scene: each shows one side of all its elements
// (Documentation/Method.md, section 10).
#pragma once

#include "Vec3.h"

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace mlr
{

/// Normals further apart than this (degrees) make a crease: the edge ends a surface. The
/// filter's outputs split their points at the same angle (FeatureAngle).
constexpr double CreaseAngleDegrees = 30.0;

/// One triangle's use of an edge: the edge runs from the triangle's corner `corner` to the
/// next one.
struct EdgeUse
{
  std::uint32_t triangle;
  std::uint32_t corner;
};

/// Calls visit(u, v) once for every two triangles that share an edge (the same two point
/// indices, in either direction): edges in the order of their points, each edge's uses in
/// triangle order. At an edge of more than two triangles, every pair.
void forEachSharedEdge(const std::vector<std::array<std::uint32_t, 3>>& triangles,
  const std::function<void(const EdgeUse&, const EdgeUse&)>& visit);

/**
 * The surface region of every triangle of a mesh (`normals`: one unit normal per triangle).
 * Two triangles sharing an edge are in one region when their normals are at most
 * CreaseAngleDegrees apart and they run along the edge in opposite directions (consistently
 * oriented: a front is a front across the region); at an edge of more than two triangles,
 * every such pair joins. Regions are numbered from 0 in the order of their first triangle,
 * so that the numbering depends on the mesh alone.
 */
std::vector<std::uint32_t> surfaceRegions(
  const std::vector<std::array<std::uint32_t, 3>>& triangles, const std::vector<Vec3>& normals);

} // namespace mlr
