#include "AccuracyBenchmarks.h"

#include "Error.h"
#include "ErrorEstimate.h"
#include "GeneratedScenes.h"
#include "ProcessMeasures.h"
#include "RigBenchmarks.h"
#include "Solver.h"
#include "SunPath.h"
#include "TownScenes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <sstream>
#include <vector>

namespace mlr::bench
{
namespace
{

/// A scene with a light whose positions can be taken in runs: rig(first, count) lights
/// frames first .. first + count - 1 of the animation.
struct Scenario
{
  std::string name;  ///< printed
  std::string cache; ///< the reference's cache name (shared with the rig cases)
  PatchMesh mesh;
  Scene scene;
  std::size_t frames;
  std::function<LightRig(std::size_t first, std::size_t count)> rig;
};

Scenario paperRoom(std::size_t frames)
{
  const scenes::PaperRoom room = scenes::paperScaleRoom(frames);
  const auto light = room.light;
  const auto translations = room.translations;
  return { "paper room (light translating on a diagonal)", "paper-room", room.mesh,
    Scene::fromPatchMesh(room.mesh), frames,
    [light, translations](std::size_t first, std::size_t count)
    {
      LightRig rig;
      rig.areaLights.emplace_back(light, Rgb(100, 100, 100),
        std::vector<Vec3>(translations.begin() + static_cast<std::ptrdiff_t>(first),
          translations.begin() + static_cast<std::ptrdiff_t>(first + count)));
      return rig;
    } };
}

/// As runTurningLight: a 1.15 m square turning 90 degrees about y at the room's centre.
Scenario turningLight(std::size_t frames)
{
  const scenes::PaperRoom room = scenes::paperScaleRoom(1);
  const Vec3 centre(2.75, 2.75, 4.8);
  const double halfTurn = 45.0 * M_PI / 180.0;
  std::vector<LightPose> poses;
  for (std::size_t k = 0; k < frames; ++k)
  {
    const double theta = halfTurn - 2 * halfTurn * double(k) / double(frames - 1);
    LightPose pose;
    pose.position = centre;
    pose.rotation = Rotation::fromQuaternion(std::cos(theta / 2), 0, std::sin(theta / 2), 0);
    poses.push_back(pose);
  }
  return { "turning light", "turning-light", room.mesh, Scene::fromPatchMesh(room.mesh), frames,
    [centre, poses](std::size_t first, std::size_t count)
    {
      LightRig rig;
      rig.areaLights.emplace_back(scenes::squareLightFacingDown(centre, 1.15), Rgb(100, 100, 100),
        std::vector<LightPose>(poses.begin() + static_cast<std::ptrdiff_t>(first),
          poses.begin() + static_cast<std::ptrdiff_t>(first + count)));
      return rig;
    } };
}

/// As runSunOverTown: 48 sun positions of 2024-06-21 over the town block.
Scenario sunOverTown()
{
  const scenes::TownBlock town = scenes::townBlock();
  const SunPathRequest request = sunOverTownRequest(town);
  std::vector<Vec3> directions;
  for (const SunPosition& s : sunPath(request))
  {
    directions.push_back(s.direction);
  }
  return { "sun over the town block", "sun-town", town.mesh, Scene::fromPatchMesh(town.mesh),
    directions.size(),
    [directions](std::size_t first, std::size_t count)
    {
      LightRig rig;
      rig.directionalLights.emplace_back(
        std::vector<Vec3>(directions.begin() + static_cast<std::ptrdiff_t>(first),
          directions.begin() + static_cast<std::ptrdiff_t>(first + count)),
        Rgb(1000, 1000, 1000));
      return rig;
    } };
}

SolverOptions baseOptions(const AccuracyCaseOptions& c)
{
  SolverOptions o;
  o.pathsPerFrame = c.paths;
  o.threads = c.threads;
  o.gatheringRatio = 1;
  o.firstBounceSurvival = 0.25;
  o.seed = 1;
  return o;
}

SolverOptions classicOptions(SolverOptions o)
{
  o.reuseShooting = false;
  o.reuseGathering = false;
  return o;
}

double at(const ReferenceRadiosity& ref, std::size_t elements, std::size_t frame,
  std::size_t element, int channel)
{
  return ref.radiosity[(frame * elements + element) * 3 + static_cast<std::size_t>(channel)];
}

/// Area-weighted mean over elements and channels of (B - B_ref)^2 in `frame`, on the
/// reference's lit sides, for radiosity `value(element, side)` (as the rig cases measure).
double frameMse(const Scene& scene, const ReferenceRadiosity& ref, std::size_t frame,
  const std::function<Rgb(std::size_t, Side)>& value)
{
  const std::size_t elements = scene.elementCount();
  double sum = 0, area = 0;
  for (std::size_t e = 0; e < elements; ++e)
  {
    const Rgb b = value(e, static_cast<Side>(ref.litSide[e]));
    double squared = 0;
    for (int c = 0; c < 3; ++c)
    {
      const double d = b[c] - at(ref, elements, frame, e, c);
      squared += d * d;
    }
    sum += scene.elementArea(e) * squared / 3;
    area += scene.elementArea(e);
  }
  return sum / area;
}

/// What a scheme cost and how far each frame is from the reference, averaged over seeds.
struct Scheme
{
  std::string name;
  double cpu = 0, wall = 0; ///< per seed
  std::vector<double> mse;  ///< per frame
  double smallestShare = 1, largestShare = 1;
};

/// One scheme's solves for one seed: fills `mse` (added) and the times (added).
using SchemeRun = std::function<void(std::uint64_t seed, std::vector<double>& mse)>;

Scheme measure(const std::string& name, std::size_t frames, int seeds, const SchemeRun& run)
{
  Scheme s;
  s.name = name;
  s.mse.assign(frames, 0.0);
  for (int seed = 0; seed < seeds; ++seed)
  {
    std::vector<double> mse(frames, 0.0);
    const double cpu = processCpuSeconds();
    const auto start = std::chrono::steady_clock::now();
    run(static_cast<std::uint64_t>(seed + 1), mse);
    s.wall +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / seeds;
    s.cpu += (processCpuSeconds() - cpu) / seeds;
    for (std::size_t f = 0; f < frames; ++f)
    {
      s.mse[f] += mse[f] / seeds;
    }
  }
  return s;
}

/// First-hit variance factor R_j of every frame for shares alpha (Documentation/Method.md,
/// "The ends of an animation"), from every element side's first-hit mass m[k][i] in frame k:
/// R_j = sum_i m_ji^2 / sum_k alpha_k m_ki / sum_i m_ji. `squares[j][i]` is an unbiased
/// estimate of m_ji^2 (the product of two independent solves' masses).
std::vector<double> firstHitFactors(const std::vector<std::vector<double>>& m,
  const std::vector<std::vector<double>>& squares, const std::vector<double>& alpha)
{
  const std::size_t n = m.size(), sides = m[0].size();
  std::vector<double> mixture(sides, 0.0), r(n, 0.0);
  for (std::size_t k = 0; k < n; ++k)
  {
    for (std::size_t i = 0; i < sides; ++i)
    {
      mixture[i] += alpha[k] * m[k][i];
    }
  }
  for (std::size_t j = 0; j < n; ++j)
  {
    double second = 0, first = 0;
    for (std::size_t i = 0; i < sides; ++i)
    {
      if (mixture[i] > 0)
      {
        second += squares[j][i] / mixture[i];
        first += m[j][i];
      }
    }
    r[j] = first > 0 ? second / first : 0;
  }
  return r;
}

/// The first-hit factor of every frame when its paths come from a window of `width`
/// positions alone, as many from each, weighed by the balance heuristic over the window (an
/// unbiased mixture estimator of its own): runs of `width` positions one after another
/// (`sliding` false, the last run may be shorter), or the run centred on the frame, shifted
/// to stay whole at the ends (`sliding` true). A path from position k then scores the frames
/// whose windows hold k, and needs the kernels of every position of those windows.
std::vector<double> windowFactors(const std::vector<std::vector<double>>& m,
  const std::vector<std::vector<double>>& squares, std::size_t width, bool sliding)
{
  const std::size_t n = m.size();
  width = std::clamp<std::size_t>(width, 1, n);
  std::vector<double> r(n, 0.0);
  for (std::size_t j = 0; j < n; ++j)
  {
    const std::size_t begin =
      sliding ? std::min(j - std::min(j, width / 2), n - width) : j / width * width;
    const std::size_t end = std::min(n, begin + width);
    std::vector<double> alpha(n, 0.0);
    for (std::size_t k = begin; k < end; ++k)
    {
      alpha[k] = 1.0 / double(end - begin);
    }
    r[j] = firstHitFactors(m, squares, alpha)[j];
  }
  return r;
}

/// The solver's balancing (Shooting.cxx) on the first-hit masses, with shares clamped to
/// [low, high] / n: shares times sqrt(R), renormalised, until the frames' R agree within 1%.
std::vector<double> balancedShares(const std::vector<std::vector<double>>& m,
  const std::vector<std::vector<double>>& squares, double low, double high, int iterations)
{
  const std::size_t n = m.size();
  std::vector<double> alpha(n, 1.0 / double(n));
  for (int it = 0; it < iterations; ++it)
  {
    const std::vector<double> r = firstHitFactors(m, squares, alpha);
    const double lowest = *std::min_element(r.begin(), r.end());
    const double highest = *std::max_element(r.begin(), r.end());
    if (!(highest > 0) || highest < 1.01 * lowest)
    {
      break;
    }
    double total = 0;
    for (std::size_t k = 0; k < n; ++k)
    {
      alpha[k] *= r[k] > 0 ? std::sqrt(r[k]) : 1.0;
      total += alpha[k];
    }
    for (double& a : alpha)
    {
      a = std::clamp(a / total, low / double(n), high / double(n));
    }
  }
  double total = 0;
  for (double a : alpha)
  {
    total += a;
  }
  for (double& a : alpha)
  {
    a /= total;
  }
  return alpha;
}

struct Curve
{
  double worst = 0, first = 0, middle = 0, last = 0, mean = 0;
  std::size_t worstFrame = 0;
};

Curve curveOf(const std::vector<double>& ratio)
{
  Curve c;
  for (std::size_t f = 0; f < ratio.size(); ++f)
  {
    if (ratio[f] > c.worst)
    {
      c.worst = ratio[f];
      c.worstFrame = f;
    }
    c.mean += ratio[f] / double(ratio.size());
  }
  c.first = ratio.front();
  c.middle = ratio[ratio.size() / 2];
  c.last = ratio.back();
  return c;
}

std::string jsonList(const std::vector<double>& values)
{
  std::ostringstream out;
  out << "[";
  for (std::size_t i = 0; i < values.size(); ++i)
  {
    out << (i ? ", " : "") << values[i];
  }
  out << "]";
  return out.str();
}

/// The ends case for one scenario; `target` is the worst frame's ratio the task asks for.
std::string endsOf(const Scenario& s, const AccuracyCaseOptions& c, double target, int window)
{
  const int seeds = c.seeds > 0 ? c.seeds : 2;
  RigCaseOptions refOptions;
  refOptions.threads = c.threads;
  refOptions.referenceFactor = c.referenceFactor > 0 ? c.referenceFactor : 32;
  refOptions.cacheDirectory = c.cacheDirectory;
  const SolverOptions base = baseOptions(c);
  const LightRig whole = s.rig(0, s.frames);
  std::printf("\n=== Ends: %s ===\n%zu patches, %zu elements, %zu frames; N = %llu, k = 1, "
              "lambda = 0.25; %d seeds per scheme\n",
    s.name.c_str(), s.scene.patchCount(), s.scene.elementCount(), s.frames,
    static_cast<unsigned long long>(base.pathsPerFrame), seeds);
  std::fflush(stdout);
  const ReferenceRadiosity ref =
    classicReference(s.cache, s.mesh, s.scene, whole, base, refOptions);

  // First-hit masses of every frame from the classic solves (two seeds: their product is an
  // unbiased square), for the share model below.
  const std::size_t sides = 2 * s.scene.elementCount();
  std::vector<std::vector<double>> mass[2];
  std::vector<Scheme> schemes;
  schemes.push_back(measure("classic", s.frames, seeds,
    [&](std::uint64_t seed, std::vector<double>& mse)
    {
      SolverOptions o = classicOptions(base);
      o.seed = seed;
      const Solution solution = solve(s.scene, whole, o);
      if (seed <= 2)
      {
        auto& m = mass[seed - 1];
        m.assign(s.frames, std::vector<double>(sides, 0.0));
        for (std::size_t f = 0; f < s.frames; ++f)
        {
          for (std::size_t e = 0; e < s.scene.elementCount(); ++e)
          {
            for (Side side : { Side::Front, Side::Back })
            {
              m[f][2 * e + static_cast<std::size_t>(side)] =
                solution.directIrradiance(f, e, side).sum() * s.scene.elementArea(e);
            }
          }
        }
      }
      for (std::size_t f = 0; f < s.frames; ++f)
      {
        mse[f] = frameMse(
          s.scene, ref, f, [&](std::size_t e, Side side) { return solution.total(f, e, side); });
      }
    }));
  // Full reuse over all positions, balanced (the solver's default, shares within 1/4 to 4
  // times N/n) or with equal shares.
  double smallest = 1, largest = 1;
  SolverStatistics equalShares; // of the last seed's equal-shares solve
  auto reuse = [&](const std::string& name, bool balance)
  {
    Scheme scheme = measure(name, s.frames, seeds,
      [&](std::uint64_t seed, std::vector<double>& mse)
      {
        SolverOptions o = base;
        o.seed = seed;
        o.balanceFrames = balance;
        const Solution solution = solve(s.scene, whole, o);
        smallest = solution.statistics.smallestPositionShare;
        largest = solution.statistics.largestPositionShare;
        if (!balance)
        {
          equalShares = solution.statistics;
        }
        for (std::size_t f = 0; f < s.frames; ++f)
        {
          mse[f] = frameMse(
            s.scene, ref, f, [&](std::size_t e, Side side) { return solution.total(f, e, side); });
        }
      });
    scheme.smallestShare = smallest;
    scheme.largestShare = largest;
    return scheme;
  };
  schemes.push_back(reuse("full reuse, balanced 1/4-4x (chosen)", true));
  schemes.push_back(reuse("full reuse, equal shares", false));
  const std::size_t equalScheme = schemes.size() - 1;
  // Windows: the positions in runs of `window`, each run reused (and balanced) on its own, so
  // that a frame weighs only the paths of the positions near it; every frame still gets N
  // effective paths, at the price of N paths per run.
  schemes.push_back(measure("windows of " +
      std::to_string(std::min<std::size_t>(static_cast<std::size_t>(window), s.frames)) +
      " positions",
    s.frames, seeds,
    [&](std::uint64_t seed, std::vector<double>& mse)
    {
      SolverOptions o = base;
      o.seed = seed;
      for (std::size_t first = 0; first < s.frames; first += static_cast<std::size_t>(window))
      {
        const std::size_t count =
          std::min<std::size_t>(static_cast<std::size_t>(window), s.frames - first);
        const Solution solution = solve(s.scene, s.rig(first, count), o);
        for (std::size_t f = 0; f < count; ++f)
        {
          mse[first + f] = frameMse(s.scene, ref, first + f,
            [&](std::size_t e, Side side) { return solution.total(f, e, side); });
        }
      }
    }));
  // Centred windows: frame j weighs only the paths of the `window` positions around it (the
  // run centred on j, shifted to stay whole at the ends), N / window from each, by the
  // balance heuristic over that window: an unbiased mixture estimator of its own for every
  // frame. Solved as one whole-reuse solve of the window per frame, whose frame j has exactly
  // that estimator's distribution, so the MSE is the scheme's; its time is not (n solves of
  // N paths where the scheme casts n N / window paths in all), and is estimated from the rays
  // instead (below).
  const std::size_t width = std::min<std::size_t>(static_cast<std::size_t>(window), s.frames);
  auto windowStart = [&](std::size_t j)
  { return std::min(j - std::min(j, width / 2), s.frames - width); };
  double windowShadow = 0, windowNearest = 0; // over the per-frame solves, per seed
  Scheme centred =
    measure("centred windows of " + std::to_string(width) + " (time from rays)", s.frames, seeds,
      [&](std::uint64_t seed, std::vector<double>& mse)
      {
        SolverOptions o = base;
        o.seed = seed;
        o.balanceFrames = false;
        for (std::size_t j = 0; j < s.frames; ++j)
        {
          const std::size_t first = windowStart(j);
          const Solution solution = solve(s.scene, s.rig(first, width), o);
          windowShadow += double(solution.statistics.shadowRays) / seeds;
          windowNearest += double(solution.statistics.shootingRays) / seeds;
          mse[j] = frameMse(s.scene, ref, j,
            [&](std::size_t e, Side side) { return solution.total(j - first, e, side); });
        }
      });
  {
    // The scheme casts N / window paths per position, n N / window in all, where the n
    // per-frame solves cast n N: a window solve's paths have the scheme's nearest-hit rays.
    // A path from position k scores the frames whose windows hold k and needs the kernels
    // (shadow rays) of every position in those windows, |U_k| - 1 others where a window
    // solve's path has window - 1: at the window solves' rate per other position, which the
    // farther positions of U_k reach no more often. Full reuse's CPU time per ray (equal
    // shares) then prices the rays; scoring (n N frame-scores) and gathering (one set of
    // rays) are the same in both and do not grow with the rays, so the estimate errs high.
    double others = 0;
    for (std::size_t k = 0; k < s.frames; ++k)
    {
      std::size_t lowest = k, highest = k;
      for (std::size_t j = 0; j < s.frames; ++j)
      {
        const std::size_t first = windowStart(j);
        if (first <= k && k < first + width)
        {
          lowest = std::min(lowest, first);
          highest = std::max(highest, first + width - 1);
        }
      }
      others += double(highest - lowest);
    }
    const double n = double(s.frames), w = double(width);
    const double shadow = windowShadow * others / (n * w * std::max(w - 1, 1.0));
    const double nearest = windowNearest / w;
    const double fullShadow = double(equalShares.shadowRays);
    const double fullNearest = double(equalShares.shootingRays);
    const Scheme& equal = schemes[equalScheme];
    const double measuredCpu = centred.cpu;
    centred.cpu = equal.cpu * (shadow + nearest) / std::max(fullShadow + fullNearest, 1.0);
    centred.wall *= centred.cpu / std::max(measuredCpu, 1e-9);
    std::printf("Centred windows of %zu, estimated: %.2fx full reuse's shadow rays and %.2fx its "
                "nearest-hit rays, %.3f CPU s (measured as %zu solves: %.3f CPU s)\n",
      width, shadow / std::max(fullShadow, 1.0), nearest / std::max(fullNearest, 1.0), centred.cpu,
      s.frames, measuredCpu);
  }
  schemes.push_back(centred);
  // A defensive share d: every frame is the count-weighted mean of full reuse with (1 - d) N
  // paths and classic with d N, both unbiased, so the mix is, with N paths per frame.
  for (const double d : { 0.05, 0.15 })
  {
    char label[64];
    std::snprintf(label, sizeof label, "defensive %.0f%% classic", 100 * d);
    schemes.push_back(measure(label, s.frames, seeds,
      [&](std::uint64_t seed, std::vector<double>& mse)
      {
        SolverOptions o = base, k = classicOptions(base);
        o.seed = seed;
        k.seed = seed + 1000;
        k.pathsPerFrame = static_cast<std::uint64_t>(std::llround(d * double(base.pathsPerFrame)));
        o.pathsPerFrame = base.pathsPerFrame - k.pathsPerFrame;
        const Solution r = solve(s.scene, whole, o);
        const Solution q = solve(s.scene, whole, k);
        const double wr = double(o.pathsPerFrame) / double(base.pathsPerFrame);
        for (std::size_t f = 0; f < s.frames; ++f)
        {
          mse[f] = frameMse(s.scene, ref, f,
            [&](std::size_t e, Side side)
            { return r.total(f, e, side) * wr + q.total(f, e, side) * (1 - wr); });
        }
      }));
  }

  const Scheme& classic = schemes[0];
  std::printf("\n%-40s %7s %7s %7s %7s %7s %6s %8s %8s %10s %10s\n", "scheme", "worst", "at",
    "first", "middle", "last", "mean", "CPU s", "speed-up", "TxMSE worst", "TxMSE mean");
  std::ostringstream json;
  json << "{\n    \"patches\": " << s.scene.patchCount()
       << ", \"elements\": " << s.scene.elementCount() << ", \"frames\": " << s.frames
       << ", \"paths_per_frame\": " << base.pathsPerFrame << ", \"seeds\": " << seeds
       << ", \"reference_paths_per_frame\": " << ref.paths << ",\n    \"schemes\": [\n";
  Curve chosen;
  double chosenSpeedup = 0;
  for (std::size_t i = 0; i < schemes.size(); ++i)
  {
    const Scheme& m = schemes[i];
    std::vector<double> ratio(s.frames);
    for (std::size_t f = 0; f < s.frames; ++f)
    {
      ratio[f] = m.mse[f] / classic.mse[f];
    }
    const Curve curve = curveOf(ratio);
    const double speedup = classic.cpu / m.cpu;
    if (i == 1)
    {
      chosen = curve;
      chosenSpeedup = speedup;
    }
    // Time x MSE against classic's, for the worst frame and for the mean of the frames.
    std::printf("%-40s %7.2f %7zu %7.2f %7.2f %7.2f %6.2f %8.2f %7.2fx %9.2fx %9.2fx\n",
      m.name.c_str(), curve.worst, curve.worstFrame + 1, curve.first, curve.middle, curve.last,
      curve.mean, m.cpu, speedup, speedup / curve.worst, speedup / curve.mean);
    json << "      {\"name\": \"" << m.name << "\", \"cpu_seconds\": " << m.cpu
         << ", \"seconds\": " << m.wall << ", \"smallest_share\": " << m.smallestShare
         << ", \"largest_share\": " << m.largestShare << ", \"mse_ratio\": " << jsonList(ratio)
         << "}" << (i + 1 < schemes.size() ? ",\n" : "\n");
  }
  for (std::size_t i = 1; i < 3; ++i)
  {
    std::printf("MSE / classic, every frame, %s:", schemes[i].name.c_str());
    for (std::size_t f = 0; f < s.frames; ++f)
    {
      std::printf(" %.2f", schemes[i].mse[f] / classic.mse[f]);
    }
    std::printf("\n");
  }
  std::printf("Balanced shares of the last seed: %.2f to %.2f of N/n (the clamps are 0.25 and 4)\n",
    schemes[1].smallestShare, schemes[1].largestShare);

  // The share model: the first-hit variance factor of every frame (the quantity the solver's
  // pilot balances) from the classic solves' direct light, for equal shares and for the
  // balancing with clamps wider than the solver's, up to none at all.
  std::vector<std::vector<double>> square(s.frames, std::vector<double>(sides, 0.0));
  std::vector<std::vector<double>> meanMass(s.frames, std::vector<double>(sides, 0.0));
  const bool twoSeeds = !mass[1].empty();
  for (std::size_t f = 0; f < s.frames; ++f)
  {
    for (std::size_t i = 0; i < sides; ++i)
    {
      const double a = mass[0][f][i], b = twoSeeds ? mass[1][f][i] : a;
      square[f][i] = a * b;
      meanMass[f][i] = (a + b) / 2;
    }
  }
  std::printf("First-hit variance factor R (Method.md), from the classic solves' direct light%s:\n",
    twoSeeds ? "" : " (one seed: R biased upwards)");
  std::printf("%-34s %7s %7s %7s %7s %7s %8s %8s\n", "shares", "worst", "first", "middle", "last",
    "mean", "lowest", "highest");
  json << "    ],\n    \"first_hit_factor\": [\n";
  struct Clamp
  {
    const char* name;
    double low, high;
  };
  const Clamp clamps[] = { { "equal", 1, 1 }, { "balanced, 1/4-4x (the solver's)", 0.25, 4 },
    { "balanced, 1/8-8x", 0.125, 8 }, { "balanced, 1/16-16x", 1.0 / 16, 16 },
    { "balanced, unclamped", 1e-6, 1e6 } };
  for (const Clamp& clamp : clamps)
  {
    const std::vector<double> alpha =
      balancedShares(meanMass, square, clamp.low, clamp.high, clamp.high >= 1e6 ? 400 : 40);
    const Curve curve = curveOf(firstHitFactors(meanMass, square, alpha));
    const double n = double(s.frames);
    std::printf("%-34s %7.2f %7.2f %7.2f %7.2f %7.2f %8.2f %8.2f\n", clamp.name, curve.worst,
      curve.first, curve.middle, curve.last, curve.mean,
      n * *std::min_element(alpha.begin(), alpha.end()),
      n * *std::max_element(alpha.begin(), alpha.end()));
    json << "      {\"shares\": \"" << clamp.name << "\", \"worst\": " << curve.worst
         << ", \"mean\": " << curve.mean << "}" << (&clamp != &clamps[4] ? ",\n" : "\n");
  }
  // Windows: runs of `width` positions (the windows scheme above, but with equal shares
  // where that scheme balances each run), and the window centred on each frame (the
  // centred-windows scheme), equal shares within the window.
  json << "    ],\n    \"first_hit_factor_windows\": [\n";
  for (const bool sliding : { false, true })
  {
    const Curve curve = curveOf(windowFactors(meanMass, square, width, sliding));
    char label[64];
    std::snprintf(
      label, sizeof label, "%s of %zu positions", sliding ? "centred windows" : "runs", width);
    std::printf("%-34s %7.2f %7.2f %7.2f %7.2f %7.2f\n", label, curve.worst, curve.first,
      curve.middle, curve.last, curve.mean);
    json << "      {\"shares\": \"" << label << "\", \"worst\": " << curve.worst
         << ", \"mean\": " << curve.mean << "}" << (sliding ? "\n" : ",\n");
  }
  std::printf("(runs cast N paths per run; centred windows N / %zu per position, %zu frames and up "
              "to %zu kernels per path)\n",
    width, width, 2 * width - 1);
  json << "    ]";
  std::printf("Target: every frame within %.2fx of classic (balanced, chosen): worst %.2f, %s; "
              "full reuse %.1fx faster than classic in CPU time\n",
    target, chosen.worst, chosen.worst <= target ? "met" : "MISSED", chosenSpeedup);
  std::printf("MSE in (W/m^2)^2 on the reference's lit sides, area-weighted, mean over the seeds; "
              "it includes the reference's own error (about 1/%d of classic's). CPU s per seed: "
              "the process's user + system time, which other processes hardly change.\n",
    refOptions.referenceFactor);
  json << ",\n    \"speedup_cpu\": " << chosenSpeedup << ", \"worst\": " << chosen.worst
       << ", \"target\": " << target << "\n  }";
  return json.str();
}

/// Lit as the solver counts it (ErrorEstimate.h): the reference's radiosity (lit side, sum
/// over channels) above LitFractionOfMean of the frame's mean over all elements.
std::vector<char> litElements(
  const ReferenceRadiosity& ref, std::size_t elements, std::size_t frame)
{
  double mean = 0;
  for (std::size_t e = 0; e < elements; ++e)
  {
    for (int c = 0; c < 3; ++c)
    {
      mean += at(ref, elements, frame, e, c) / double(elements);
    }
  }
  std::vector<char> lit(elements, 0);
  for (std::size_t e = 0; e < elements; ++e)
  {
    const double b = at(ref, elements, frame, e, 0) + at(ref, elements, frame, e, 1) +
      at(ref, elements, frame, e, 2);
    lit[e] = b > LitFractionOfMean * mean ? 1 : 0;
  }
  return lit;
}

} // namespace

std::string runEnds(const AccuracyCaseOptions& c)
{
  const std::size_t frames = c.frames > 0 ? c.frames : 30;
  if (frames < 3)
  {
    throw Error("the ends case needs at least 3 frames (--frames)");
  }
  std::ostringstream json;
  json << "{\n  \"paper_room\": " << endsOf(paperRoom(frames), c, 1.25, 10);
  json << ",\n  \"turning_light\": " << endsOf(turningLight(frames), c, 1.25, 10);
  json << ",\n  \"sun_over_town\": " << endsOf(sunOverTown(), c, 1.5, 12) << "\n  }";
  return json.str();
}

std::string runErrorBars(const AccuracyCaseOptions& c)
{
  const int seeds = c.seeds > 0 ? c.seeds : 20;
  constexpr std::uint64_t Batches = 16;
  const Scenario s = paperRoom(c.frames > 0 ? c.frames : 30);
  const LightRig rig = s.rig(0, s.frames);
  const SolverOptions base = baseOptions(c);
  RigCaseOptions refOptions;
  refOptions.threads = c.threads;
  refOptions.referenceFactor = c.referenceFactor > 0 ? c.referenceFactor : 32;
  refOptions.cacheDirectory = c.cacheDirectory;
  std::printf("\n=== Error bars: %s ===\n%zu elements, %zu frames; full reuse, N = %llu, %llu "
              "error batches, %d seeds\n",
    s.name.c_str(), s.scene.elementCount(), s.frames,
    static_cast<unsigned long long>(base.pathsPerFrame), static_cast<unsigned long long>(Batches),
    seeds);
  std::fflush(stdout);
  const ReferenceRadiosity ref = classicReference(s.cache, s.mesh, s.scene, rig, base, refOptions);
  const std::size_t elements = s.scene.elementCount(), frames = s.frames;
  std::vector<std::vector<char>> lit;
  for (std::size_t f = 0; f < frames; ++f)
  {
    lit.push_back(litElements(ref, elements, f));
  }

  // The reference's own variance, which the squared errors against it contain: classic's
  // squared standard error at N, from one batched classic solve, over the reference factor.
  std::vector<double> referenceVariance(frames, 0.0);
  {
    SolverOptions o = classicOptions(base);
    o.errorBatches = Batches;
    o.seed = 777;
    const Solution k = solve(s.scene, rig, o);
    for (std::size_t f = 0; f < frames; ++f)
    {
      std::size_t count = 0;
      for (std::size_t e = 0; e < elements; ++e)
      {
        if (lit[f][e])
        {
          const Rgb se = k.radiosityStdError(f, e, static_cast<Side>(ref.litSide[e]));
          for (int c3 = 0; c3 < 3; ++c3)
          {
            referenceVariance[f] += se[c3] * se[c3];
            ++count;
          }
        }
      }
      referenceVariance[f] /= double(count) * refOptions.referenceFactor;
    }
  }

  std::vector<double> squaredError(frames, 0.0), squaredSe(frames, 0.0), covered(frames, 0.0);
  std::vector<double> count(frames, 0.0), squaredErrorOne(frames, 0.0);
  double seconds = 0;
  for (int seed = 0; seed < seeds; ++seed)
  {
    SolverOptions o = base;
    o.errorBatches = Batches;
    o.seed = 1000 + static_cast<std::uint64_t>(seed);
    const Solution run = solve(s.scene, rig, o);
    seconds += run.statistics.secondsTotal / seeds;
    // One solve with the same seed and N: gathering's and shooting's errors multiply within a batch
    // (Method 17), so the batches' mean may be noisier than one solve of their paths.
    SolverOptions single = o;
    single.errorBatches = 1;
    const Solution one = solve(s.scene, rig, single);
    for (std::size_t f = 0; f < frames; ++f)
    {
      for (std::size_t e = 0; e < elements; ++e)
      {
        if (lit[f][e])
        {
          const Rgb b = one.total(f, e, static_cast<Side>(ref.litSide[e]));
          for (int c3 = 0; c3 < 3; ++c3)
          {
            const double d = b[c3] - at(ref, elements, f, e, c3);
            squaredErrorOne[f] += d * d;
          }
        }
      }
    }
    for (std::size_t f = 0; f < frames; ++f)
    {
      for (std::size_t e = 0; e < elements; ++e)
      {
        if (!lit[f][e])
        {
          continue;
        }
        const Side side = static_cast<Side>(ref.litSide[e]);
        const Rgb b = run.total(f, e, side), se = run.radiosityStdError(f, e, side);
        for (int c3 = 0; c3 < 3; ++c3)
        {
          const double d = b[c3] - at(ref, elements, f, e, c3);
          squaredError[f] += d * d;
          squaredSe[f] += se[c3] * se[c3];
          covered[f] += std::abs(d) <= se[c3] ? 1 : 0;
          count[f] += 1;
        }
      }
    }
  }

  std::printf("\n%6s %8s %12s %12s %12s %9s %9s\n", "frame", "lit", "RMS error", "ref. noise",
    "mean SE", "RMS / SE", "1-sigma");
  double worstRatio = 1, lowCoverage = 1, highCoverage = 0, allCovered = 0, all = 0;
  std::ostringstream json;
  json << "{\n    \"elements\": " << elements << ", \"frames\": " << frames
       << ", \"paths_per_frame\": " << base.pathsPerFrame << ", \"batches\": " << Batches
       << ", \"seeds\": " << seeds << ", \"reference_paths_per_frame\": " << ref.paths
       << ", \"seconds_per_solve\": " << seconds << ",\n    \"per_frame\": [\n";
  for (std::size_t f = 0; f < frames; ++f)
  {
    // RMS error against the expectation: the squared error against the reference, less the
    // reference's own variance.
    const double raw = std::sqrt(squaredError[f] / count[f]);
    const double rms = std::sqrt(std::max(0.0, squaredError[f] / count[f] - referenceVariance[f]));
    const double se = std::sqrt(squaredSe[f] / count[f]);
    const double coverage = covered[f] / count[f];
    const double ratio = rms / se;
    worstRatio = std::abs(ratio - 1) > std::abs(worstRatio - 1) ? ratio : worstRatio;
    lowCoverage = std::min(lowCoverage, coverage);
    highCoverage = std::max(highCoverage, coverage);
    allCovered += covered[f];
    all += count[f];
    std::printf("%6zu %8.0f %12.4g %12.4g %12.4g %9.3f %8.1f%%\n", f + 1, count[f] / 3 / seeds, raw,
      std::sqrt(referenceVariance[f]), se, ratio, 100 * coverage);
    json << "      {\"frame\": " << f + 1 << ", \"rms_error\": " << rms
         << ", \"rms_error_raw\": " << raw << ", \"mean_se\": " << se << ", \"ratio\": " << ratio
         << ", \"coverage\": " << coverage << "}" << (f + 1 < frames ? ",\n" : "\n");
  }
  // MSE against the expectation (less the reference's variance) of the batches' mean over
  // one solve's, per frame.
  std::vector<double> batchCost(frames);
  for (std::size_t f = 0; f < frames; ++f)
  {
    const double batched = squaredError[f] / count[f] - referenceVariance[f];
    const double single = squaredErrorOne[f] / count[f] - referenceVariance[f];
    batchCost[f] = single > 0 ? batched / single : 0;
  }
  const Curve batchCurve = curveOf(batchCost);
  std::printf("MSE of the %llu batches' mean over one solve's with the same seeds: mean "
              "of the frames %.3f, highest %.3f (frame %zu)\n",
    static_cast<unsigned long long>(Batches), batchCurve.mean, batchCurve.worst,
    batchCurve.worstFrame + 1);
  const bool ratioMet = std::abs(worstRatio - 1) <= 0.2;
  const bool coverageMet = lowCoverage >= 0.60 && highCoverage <= 0.75;
  std::printf("RMS error: over %d seeds, lit values (element, channel) of each frame, against "
              "the reference less its own variance (classic's SE^2 / %d); mean SE: the RMS of "
              "the reported standard errors. Radiosity in W/m^2. One solve took %.2f s.\n",
    seeds, refOptions.referenceFactor, seconds);
  std::printf("Target: every frame's RMS error within 20%% of the mean SE: farthest %.3f, %s; "
              "1-sigma coverage 60-75%%: %.1f%% to %.1f%% (all frames %.1f%%; Student's t, 15 "
              "degrees of freedom, gives 66.7%%), %s\n",
    worstRatio, ratioMet ? "met" : "MISSED", 100 * lowCoverage, 100 * highCoverage,
    100 * allCovered / all, coverageMet ? "met" : "MISSED");
  json << "    ], \"batches_mse_over_one_solve\": " << jsonList(batchCost)
       << ", \"farthest_ratio\": " << worstRatio << ", \"coverage_lowest\": " << lowCoverage
       << ", \"coverage_highest\": " << highCoverage << "\n  }";
  return json.str();
}

std::string runTargetError(const AccuracyCaseOptions& c)
{
  const Scenario s = paperRoom(c.frames > 0 ? c.frames : 10);
  const LightRig rig = s.rig(0, s.frames);
  SolverOptions o = baseOptions(c);
  o.errorBatches = 16;
  o.targetRelativeError = c.target;
  o.log = [](const std::string& message)
  {
    std::printf("  solver: %s\n", message.c_str());
    std::fflush(stdout);
  };
  std::printf("\n=== Target error: %s ===\n%zu elements, %zu frames; full reuse, first round "
              "N = %llu in 16 batches, target %.3g\n",
    s.name.c_str(), s.scene.elementCount(), s.frames,
    static_cast<unsigned long long>(o.pathsPerFrame), c.target);
  std::fflush(stdout);
  const double cpu = processCpuSeconds();
  const Solution run = solve(s.scene, rig, o);
  const double cpuTaken = processCpuSeconds() - cpu;
  const ErrorEstimateSummary& est = run.errorEstimate;
  double reportedP95 = 0;
  for (double p : est.relativeErrorP95)
  {
    reportedP95 = std::max(reportedP95, p);
  }
  std::printf("Took %llu paths per frame in %llu batches and %llu rounds, %.2f s (CPU %.2f s); "
              "stopped by: %s; reported 95th percentile %.4f (worst frame)\n",
    static_cast<unsigned long long>(est.pathsPerFrame),
    static_cast<unsigned long long>(est.batches), static_cast<unsigned long long>(est.rounds),
    run.statistics.secondsTotal, cpuTaken, est.stoppedBy.c_str(), reportedP95);
  std::fflush(stdout);

  // Against a reference of F times the paths taken, with its own standard errors: full
  // reuse (unbiased, Testing/Core/TestReuse.cxx) in 16 batches and another seed, since a
  // classic solve of F times tens of millions of paths per frame would take hours here.
  const int factor = c.referenceFactor > 0 ? c.referenceFactor : 2;
  SolverOptions refOptions = baseOptions(c);
  refOptions.pathsPerFrame = est.pathsPerFrame * static_cast<std::uint64_t>(factor);
  refOptions.errorBatches = 16;
  refOptions.seed = 424242;
  std::printf("Reference: full reuse, %llu paths per frame (%dx), 16 batches, seed %llu ...\n",
    static_cast<unsigned long long>(refOptions.pathsPerFrame), factor,
    static_cast<unsigned long long>(refOptions.seed));
  std::fflush(stdout);
  const Solution refRun = solve(s.scene, rig, refOptions);
  std::printf("           computed in %.1f s\n", refRun.statistics.secondsTotal);
  ReferenceRadiosity ref;
  ref.paths = refOptions.pathsPerFrame;
  ref.litSide.resize(s.scene.elementCount());
  ref.radiosity.resize(s.frames * s.scene.elementCount() * 3);
  for (std::size_t e = 0; e < s.scene.elementCount(); ++e)
  {
    ref.litSide[e] = static_cast<std::uint8_t>(refRun.litSide(e));
    for (std::size_t f = 0; f < s.frames; ++f)
    {
      const Rgb b = refRun.total(f, e, refRun.litSide(e));
      for (int c3 = 0; c3 < 3; ++c3)
      {
        ref.radiosity[(f * s.scene.elementCount() + e) * 3 + static_cast<std::size_t>(c3)] = b[c3];
      }
    }
  }
  const std::size_t elements = s.scene.elementCount();
  // Per frame, over the lit elements: the 95th percentile of the measured relative error
  // |sum_c (B - B_ref)| / sum_c B_ref, the same percentile predicted from the reported
  // standard errors for normal errors, and the RMS of the measured over the reported.
  double worstMeasured = 0, worstPredicted = 0, worstAchieved = 0, rmsSum = 0, rmsCount = 0;
  std::printf("\n%6s %10s %12s %12s %12s %10s\n", "frame", "reported", "measured p95",
    "expected p95", "achieved", "RMS / SE");
  std::ostringstream json;
  json << "{\n    \"target\": " << c.target << ", \"paths_per_frame\": " << est.pathsPerFrame
       << ", \"batches\": " << est.batches << ", \"rounds\": " << est.rounds
       << ", \"stopped_by\": \"" << est.stoppedBy
       << "\", \"seconds\": " << run.statistics.secondsTotal << ", \"cpu_seconds\": " << cpuTaken
       << ", \"reference_paths_per_frame\": " << ref.paths << ",\n    \"per_frame\": [\n";
  for (std::size_t f = 0; f < s.frames; ++f)
  {
    const std::vector<char> lit = litElements(ref, elements, f);
    std::vector<double> measured, sigma;
    double squared = 0, expected = 0;
    for (std::size_t e = 0; e < elements; ++e)
    {
      if (!lit[e])
      {
        continue;
      }
      const Side side = static_cast<Side>(ref.litSide[e]);
      const double b =
        at(ref, elements, f, e, 0) + at(ref, elements, f, e, 1) + at(ref, elements, f, e, 2);
      const double x = run.total(f, e, side).sum();
      // The difference's standard error: the run's and the reference's, independent.
      const double own = run.radiosityStdError(f, e, side).sum();
      const double theirs = refRun.radiosityStdError(f, e, side).sum();
      const double se = std::sqrt(own * own + theirs * theirs);
      measured.push_back(std::abs(x - b) / b);
      sigma.push_back(se / b);
      squared += (x - b) * (x - b) / (b * b);
      expected += se * se / (b * b);
    }
    std::vector<double> sorted = measured;
    std::sort(sorted.begin(), sorted.end());
    const double p95 = sorted[std::min(
      sorted.size() - 1, static_cast<std::size_t>(std::ceil(0.95 * double(sorted.size()))) - 1)];
    // The x with sum_i P(|N(0, sigma_i)| > x) = 5% of the elements, by bisection.
    double lo = 0, hi = 10 * *std::max_element(sigma.begin(), sigma.end());
    for (int it = 0; it < 60; ++it)
    {
      const double mid = (lo + hi) / 2;
      double beyond = 0;
      for (double sg : sigma)
      {
        beyond += sg > 0 ? std::erfc(mid / (sg * std::sqrt(2.0))) : 0;
      }
      (beyond > 0.05 * double(sigma.size()) ? lo : hi) = mid;
    }
    const double predicted = (lo + hi) / 2;
    const double reported = est.relativeErrorP95[f];
    // The p95 of the relative standard error that the measured errors imply.
    const double achieved = reported * p95 / predicted;
    const double rms = std::sqrt(squared / expected);
    worstMeasured = std::max(worstMeasured, p95);
    worstPredicted = std::max(worstPredicted, predicted);
    worstAchieved = std::max(worstAchieved, achieved);
    rmsSum += rms;
    rmsCount += 1;
    std::printf(
      "%6zu %10.4f %12.4f %12.4f %12.4f %10.3f\n", f + 1, reported, p95, predicted, achieved, rms);
    json << "      {\"frame\": " << f + 1 << ", \"reported_p95\": " << reported
         << ", \"measured_p95\": " << p95 << ", \"expected_p95\": " << predicted
         << ", \"achieved_p95\": " << achieved << ", \"rms_over_se\": " << rms << "}"
         << (f + 1 < s.frames ? ",\n" : "\n");
  }
  std::printf("reported: the solver's 95th percentile of the relative standard error; measured "
              "p95: of |B - B_ref| / B_ref; expected p95: what the reported standard errors (the "
              "run's and the reference's, %dx the paths) predict for it with normal errors; "
              "achieved: reported x measured / expected, the 95th percentile of the relative "
              "standard error the reference confirms.\n",
    factor);
  std::printf("Target: the 95th percentile at or below %.3g against the reference: achieved "
              "%.4f (worst frame), %s; mean RMS / SE %.3f\n",
    c.target, worstAchieved, worstAchieved <= c.target ? "met" : "MISSED", rmsSum / rmsCount);
  json << "    ], \"achieved_p95\": " << worstAchieved << ", \"measured_p95\": " << worstMeasured
       << ", \"expected_p95\": " << worstPredicted << "\n  }";
  return json.str();
}

} // namespace mlr::bench
