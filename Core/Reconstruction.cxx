#include "Reconstruction.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace mlr
{

namespace
{
/// Neighbours whose normals differ by more than this (about 8 degrees) are another surface:
/// across a crease the light need not be continuous.
constexpr double CoplanarCosine = 0.99;

/// The gradients of `s` from its neighbours' centroid offsets in its plane:
/// g = A^+ sum_i d_i (v_i - v_t) with A = sum_i d_i d_i^T, so neighbour i's difference has the
/// gradient A^+ d_i. With the offsets along one line (one neighbour, or three in a row) A^+
/// keeps that line only.
void solveGradients(LinearStencil& s, const Vec3& normal,
  const std::array<Vec3, LinearStencil::MaxNeighbours>& d, const std::array<Vec3, 3>& corners)
{
  Vec3 u, w;
  orthonormalBasis(normal, u, w);
  double a = 0, b = 0, c = 0; // A = [[a, b], [b, c]] in the basis (u, w)
  for (int i = 0; i < s.count; ++i)
  {
    const double x = dot(d[static_cast<std::size_t>(i)], u),
                 y = dot(d[static_cast<std::size_t>(i)], w);
    a += x * x;
    b += x * y;
    c += y * y;
  }
  const double trace = a + c, det = a * c - b * b;
  if (!(trace > 0))
  {
    s.count = 0;
    return;
  }
  // Rank one: A = trace e e^T along the offsets' common direction e, a row of A.
  const double ex = a >= c ? a : b, ey = a >= c ? b : c;
  const double norm = std::hypot(ex, ey);
  const bool full = det > 1e-6 * trace * trace;
  for (int i = 0; i < s.count; ++i)
  {
    const double x = dot(d[static_cast<std::size_t>(i)], u),
                 y = dot(d[static_cast<std::size_t>(i)], w);
    double gx = 0, gy = 0;
    if (full)
    {
      gx = (c * x - b * y) / det;
      gy = (a * y - b * x) / det;
    }
    else
    {
      const double along = (x * ex + y * ey) / (norm * trace);
      gx = along * ex / norm;
      gy = along * ey / norm;
    }
    const Vec3 gradient = u * gx + w * gy;
    for (std::size_t k = 0; k < 3; ++k)
    {
      s.weights[k][static_cast<std::size_t>(i)] = dot(corners[k], gradient);
    }
  }
}
}

void LinearStencil::elementValues(const Rgb& value, const Rgb* neighbours, Rgb* out) const
{
  out[3] = value;
  // Each channel has its own phi: a channel that the limiter takes to zero is zero exactly, so
  // a colour whose channels are in one ratio everywhere keeps it there.
  for (int c = 0; c < 3; ++c)
  {
    double change[3] = { 0, 0, 0 };
    double phi = 1;
    for (std::size_t k = 0; k < 3; ++k)
    {
      for (int i = 0; i < this->count; ++i)
      {
        change[k] += this->weights[k][static_cast<std::size_t>(i)] * (neighbours[i][c] - value[c]);
      }
      if (change[k] < 0)
      {
        phi = std::min(phi, -value[c] / change[k]);
      }
    }
    phi = std::max(phi, 0.0);
    for (std::size_t k = 0; k < 3; ++k)
    {
      // Where the limiter takes the channel to zero, the sum leaves a residue of rounding, not
      // of light: zero it.
      const double moved = phi * change[k];
      const double x = value[c] + moved;
      out[k][c] = std::abs(x) <= 1e-12 * (std::abs(value[c]) + std::abs(moved)) ? 0.0 : x;
    }
  }
}

std::vector<LinearStencil> linearStencils(const std::vector<Vec3>& points,
  const std::vector<std::array<std::uint32_t, 3>>& triangles, const std::vector<Vec3>& normals,
  const std::vector<Rgb>& reflectance)
{
  auto key = [](std::uint32_t a, std::uint32_t b)
  { return (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b); };
  auto edge = [&](std::size_t t, int i)
  {
    return key(triangles[t][static_cast<std::size_t>(i)],
      triangles[t][static_cast<std::size_t>((i + 1) % 3)]);
  };
  // Every edge's triangles, in triangle order.
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> edges;
  edges.reserve(triangles.size() * 2);
  for (std::size_t t = 0; t < triangles.size(); ++t)
  {
    for (int i = 0; i < 3; ++i)
    {
      edges[edge(t, i)].push_back(static_cast<std::uint32_t>(t));
    }
  }
  std::vector<Vec3> centroids(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
  {
    const auto& v = triangles[t];
    centroids[t] = (points[v[0]] + points[v[1]] + points[v[2]]) / 3.0;
  }

  std::vector<LinearStencil> stencils(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
  {
    LinearStencil& s = stencils[t];
    const Vec3& n = normals[t];
    const Rgb& rho = reflectance[t];
    std::array<Vec3, LinearStencil::MaxNeighbours> offsets{};
    for (int i = 0; i < 3; ++i)
    {
      // The first neighbour across the edge that continues the surface (one per edge, where
      // more than two triangles share it).
      for (const std::uint32_t q : edges[edge(t, i)])
      {
        const double c = dot(n, normals[q]);
        const Rgb& r = reflectance[q];
        if (q == t || std::abs(c) < CoplanarCosine || r.r != rho.r || r.g != rho.g || r.b != rho.b)
        {
          continue;
        }
        const auto slot = static_cast<std::size_t>(s.count++);
        const Vec3 d = centroids[q] - centroids[t];
        s.neighbour[slot] = q;
        s.flipped[slot] = c < 0;
        offsets[slot] = d - n * dot(d, n);
        break;
      }
    }
    if (s.count > 0)
    {
      // A corner element's centroid lies halfway from the patch's centroid to the corner.
      std::array<Vec3, 3> corners;
      for (std::size_t k = 0; k < 3; ++k)
      {
        corners[k] = (points[triangles[t][k]] - centroids[t]) * 0.5;
      }
      solveGradients(s, n, offsets, corners);
    }
  }
  return stencils;
}

} // namespace mlr
