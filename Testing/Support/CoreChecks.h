// Checks the Core test suites share: expected errors, the closed-enclosure energy balance,
// exact form factors of elements and the comparison of means over seeds.
#pragma once

#include "Error.h"
#include "FormFactor.h"
#include "LightSource.h"
#include "Parallel.h"
#include "PolygonTriangulation.h"
#include "RayTracer.h"
#include "Reachability.h"
#include "Scene.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

namespace mlr::checks
{

/// The same results to the last bit (solutions whose sums must not depend on threads or ranks).
template <typename Stored, typename Allocator>
bool sameBits(const std::vector<Stored, Allocator>& a, const std::vector<Stored, Allocator>& b)
{
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Stored)) == 0;
}

/// The flags of the patch sides light can reach (patch * 2 + side), and of those the light
/// probes hit first, that a solve of `rig` finds and its memory plan counts
/// (planSolveMemory).
struct Reached
{
  std::vector<std::uint8_t> sides, firstHits;
};
inline Reached reachableOf(const Scene& scene, const LightRig& rig, const SolverOptions& options)
{
  const std::vector<MovingLight> emitters = sceneEmitters(scene);
  const RayTracer tracer(scene);
  std::uint64_t rays = 0;
  Reached r;
  r.sides = reachableSides(
    scene, tracer, lightSources(scene, rig, emitters), options, resolveThreadCount(options.threads),
    [](double) { return true; }, rays, &r.firstHits);
  return r;
}

/// Runs `action`, expects mlr::Error, and checks that its message contains `words`.
template <typename Action>
void expectError(Action action, const std::string& words)
{
  try
  {
    action();
    ADD_FAILURE() << "no error; expected one mentioning \"" << words << "\"";
  }
  catch (const Error& e)
  {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << "message: " << e.what();
  }
}

/// Runs `action`, expects mlr::Error, and returns its message.
template <typename Action>
std::string errorOf(Action action)
{
  try
  {
    action();
  }
  catch (const Error& e)
  {
    return e.what();
  }
  ADD_FAILURE() << "no mlr::Error";
  return {};
}

/// The power balance of one frame, over both sides of every element.
struct Balance
{
  Rgb absorbed;     ///< sum_i A_i (1 - rho_i) / rho_i B_i: equals Phi in a closed enclosure
  Rgb radiantPower; ///< sum_i A_i B_i: Phi rho / (1 - rho) in one of uniform reflectance rho
};

inline Balance balanceOfFrame(const Scene& scene, const Solution& solution, std::size_t frame)
{
  Balance b;
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    const Rgb& rho = scene.elementReflectance(e);
    for (Side side : { Side::Front, Side::Back })
    {
      const Rgb B = solution.total(frame, e, side);
      for (int c = 0; c < 3; ++c)
      {
        b.absorbed[c] += scene.elementArea(e) * (1 - rho[c]) / rho[c] * B[c];
        b.radiantPower[c] += scene.elementArea(e) * B[c];
      }
    }
  }
  return b;
}

/// Options for classic (reuse false) or full reuse, on 2 threads (the result does not depend
/// on the thread count; tests share the machine).
inline SolverOptions modeOptions(bool reuse, std::uint64_t paths, std::uint64_t seed)
{
  SolverOptions o;
  o.pathsPerFrame = paths;
  o.reuseShooting = reuse;
  o.reuseGathering = reuse;
  o.seed = seed;
  o.threads = 2;
  return o;
}

/**
 * The form factor from triangle (a, b, c) with unit normal `normal` to a planar polygon that
 * emits from the side its right-hand-rule normal points to: Lambert's point formula averaged
 * over a 4^depth-triangle midpoint subdivision (its error is far below the Monte Carlo noise),
 * counting only points in front of the polygon's plane.
 */
inline double elementFormFactor(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& normal,
  const std::vector<Vec3>& polygon, int depth = 4)
{
  if (depth == 0)
  {
    const Vec3 point = (a + b + c) / 3.0;
    const bool inFront = dot(point - polygon[0], newellNormal(polygon)) > 0;
    return inFront ? pointToPolygonFormFactor(point, normal, polygon) : 0.0;
  }
  const Vec3 ab = (a + b) * 0.5, bc = (b + c) * 0.5, ca = (c + a) * 0.5;
  return 0.25 *
    (elementFormFactor(a, ab, ca, normal, polygon, depth - 1) +
      elementFormFactor(ab, b, bc, normal, polygon, depth - 1) +
      elementFormFactor(ca, bc, c, normal, polygon, depth - 1) +
      elementFormFactor(ab, bc, ca, normal, polygon, depth - 1));
}

/// The power leaving each group of elements (sum of A B over both sides, one channel) in
/// every frame, as [frame * groups + group]: aggregates whose noise a few dozen seeds resolve.
inline std::vector<double> groupPowers(const Scene& scene, const Solution& solution,
  std::size_t groups, const std::function<std::size_t(std::size_t)>& groupOf, int channel)
{
  std::vector<double> power(groups * solution.frameCount(), 0.0);
  for (std::size_t f = 0; f < solution.frameCount(); ++f)
  {
    for (std::size_t e = 0; e < scene.elementCount(); ++e)
    {
      const Rgb B = solution.total(f, e, Side::Front) + solution.total(f, e, Side::Back);
      power[f * groups + groupOf(e)] += scene.elementArea(e) * B[channel];
    }
  }
  return power;
}

/// Sums of values and of their squares over independent runs (seeds).
struct SeedMoments
{
  int runs = 0;
  std::vector<double> sum, sumSquares;

  void add(const std::vector<double>& values)
  {
    sum.resize(values.size(), 0.0);
    sumSquares.resize(values.size(), 0.0);
    for (std::size_t i = 0; i < values.size(); ++i)
    {
      sum[i] += values[i];
      sumSquares[i] += values[i] * values[i];
    }
    ++runs;
  }
  double mean(std::size_t i) const { return sum[i] / runs; }
  /// The squared standard error of the mean, from the spread over the runs.
  double meanVariance(std::size_t i) const
  {
    const double m = mean(i);
    return std::max(0.0, (sumSquares[i] / runs - m * m)) / (runs - 1);
  }
};

/**
 * Expects the means of `a` and of the sum of `b` (one or more independent estimators) to
 * agree value by value within 4 standard errors from their spreads over seeds, and the mean
 * square of the z-scores to stay below 2 (1 for unbiased estimators). Returns that mean square.
 */
inline double expectSameMeans(
  const SeedMoments& a, const std::vector<const SeedMoments*>& b, const std::string& what)
{
  double chiSquare = 0;
  for (std::size_t i = 0; i < a.sum.size(); ++i)
  {
    double meanB = 0, variance = a.meanVariance(i);
    for (const SeedMoments* m : b)
    {
      meanB += m->mean(i);
      variance += m->meanVariance(i);
    }
    const double z = (a.mean(i) - meanB) / std::sqrt(variance);
    EXPECT_LT(std::abs(z), 4.0) << what << ", value " << i << ": " << a.mean(i) << " against "
                                << meanB << " +- " << std::sqrt(variance);
    chiSquare += z * z;
  }
  chiSquare /= double(a.sum.size());
  EXPECT_LT(chiSquare, 2.0) << what;
  return chiSquare;
}

} // namespace mlr::checks
