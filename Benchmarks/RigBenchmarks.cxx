#include "RigBenchmarks.h"

#include "BareEmbree.h"
#include "Error.h"
#include "GeneratedScenes.h"
#include "Photometry.h"
#include "PointLight.h"
#include "ProcessMeasures.h"
#include "Solver.h"
#include "SunPath.h"
#include "TownScenes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

namespace mlr::bench
{

SunPathRequest sunOverTownRequest(const scenes::TownBlock& town)
{
  SunPathRequest request;
  request.latitude = 48.85;
  request.longitude = 2.35;
  request.year = 2024;
  request.month = 6;
  request.day = 21;
  request.startHour = 8;
  request.endHour = 19.75;
  request.stepMinutes = 15;
  request.timeZoneHours = 2;
  request.north = town.north;
  request.up = town.up;
  return request;
}
namespace
{

// Bump when the solver's output for the same inputs changes, so that cached references go
// stale (the cache key covers the inputs and options, not the solver's code).
constexpr std::uint64_t ReferenceVersion = 2; // 2: lit sides per surface
constexpr std::uint64_t ReferenceSeed = 12345;
constexpr char CacheMagic[8] = { 'M', 'L', 'R', 'R', 'E', 'F', '1', '\n' };

/// FNV-1a over the inputs a reference depends on: its cache key.
class Hasher
{
public:
  void bytes(const void* data, std::size_t size)
  {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i)
    {
      this->Value = (this->Value ^ p[i]) * 1099511628211ULL;
    }
  }
  void number(double v) { this->bytes(&v, sizeof v); }
  void count(std::uint64_t v) { this->bytes(&v, sizeof v); }
  void vec(const Vec3& v)
  {
    this->number(v.x);
    this->number(v.y);
    this->number(v.z);
  }
  void rgb(const Rgb& c)
  {
    this->number(c.r);
    this->number(c.g);
    this->number(c.b);
  }
  /// The distribution's density on a fixed grid of directions: a shape that differs
  /// anywhere but between the grid's directions changes the key.
  void distribution(const IntensityDistribution& d)
  {
    for (int g = 0; g <= 180; ++g)
    {
      for (int c = 0; c < 24; ++c)
      {
        const double gamma = g * M_PI / 180, plane = c * M_PI / 12;
        this->number(d.density(Vec3(
          std::sin(gamma) * std::cos(plane), std::sin(gamma) * std::sin(plane), std::cos(gamma))));
      }
    }
  }
  void poses(const std::vector<LightPose>& poses)
  {
    for (const LightPose& pose : poses)
    {
      this->vec(pose.position);
      this->vec(pose.rotation.row0);
      this->vec(pose.rotation.row1);
      this->vec(pose.rotation.row2);
      this->rgb(pose.power);
    }
  }
  std::uint64_t value() const { return this->Value; }

private:
  std::uint64_t Value = 14695981039346656037ULL;
};

std::uint64_t referenceKey(
  const std::string& name, const PatchMesh& mesh, const LightRig& rig, const SolverOptions& options)
{
  Hasher h;
  h.count(ReferenceVersion);
  h.bytes(name.data(), name.size());
  for (const Vec3& p : mesh.points)
  {
    h.vec(p);
  }
  for (const Triangle& t : mesh.triangles)
  {
    h.bytes(t.data(), sizeof(t));
  }
  for (const Rgb& c : mesh.reflectance)
  {
    h.rgb(c);
  }
  for (const MovingLight& light : rig.areaLights)
  {
    for (const auto& polygon : light.polygons())
    {
      h.count(polygon.size());
      for (const Vec3& p : polygon)
      {
        h.vec(p);
      }
    }
    h.rgb(light.power());
    h.poses(light.poses());
    h.distribution(light.distribution());
  }
  for (const PointLight& light : rig.pointLights)
  {
    h.rgb(light.power());
    h.poses(light.poses());
    h.distribution(light.distribution());
    h.vec(light.ownPhotometricFrame().z);
    h.vec(light.ownPhotometricFrame().x);
  }
  for (const DirectionalLight& light : rig.directionalLights)
  {
    h.rgb(light.irradiance());
    for (std::size_t f = 0; f < light.frameCount(); ++f)
    {
      h.vec(light.direction(f));
      h.rgb(light.powerFactor(f));
    }
  }
  for (const Sky& sky : rig.skies)
  {
    h.count(static_cast<std::uint64_t>(sky.model()));
    h.vec(sky.up());
    h.count(sky.frameCount());
    for (std::size_t j = 0; j < sky.positions(); ++j)
    {
      h.number(sky.integral(j));
      for (std::size_t cell = 0; cell < Sky::Cells; ++cell)
      {
        h.number(sky.density(j, cell));
      }
    }
  }
  h.count(options.pathsPerFrame);
  h.number(options.gatheringRatio);
  h.number(options.firstBounceSurvival);
  h.count(options.seed);
  h.count(options.twoSided ? 1 : 0);
  return h.value();
}

/// A classic solution at many paths: the lit side's total radiosity of every element and frame.
struct Reference
{
  std::uint64_t frames = 0, elements = 0, paths = 0;
  double seconds = 0; ///< what the solve took when it was computed
  bool cached = false;
  std::string file;
  std::vector<std::uint8_t> litSide;
  std::vector<double> radiosity; ///< [frame][element][channel]

  double at(std::size_t frame, std::size_t element, int channel) const
  {
    return this
      ->radiosity[(frame * this->elements + element) * 3 + static_cast<std::size_t>(channel)];
  }
};

template <typename T>
bool readValues(std::ifstream& in, T* data, std::size_t count)
{
  in.read(reinterpret_cast<char*>(data), static_cast<std::streamsize>(count * sizeof(T)));
  return static_cast<bool>(in);
}

bool loadReference(const std::string& file, std::uint64_t key, std::size_t frames,
  std::size_t elements, Reference& ref)
{
  std::ifstream in(file, std::ios::binary);
  char magic[8];
  std::uint64_t header[4]; // key, frames, elements, paths
  if (!in || !readValues(in, magic, 8) || std::memcmp(magic, CacheMagic, 8) != 0 ||
    !readValues(in, header, 4) || header[0] != key || header[1] != frames ||
    header[2] != elements || !readValues(in, &ref.seconds, 1))
  {
    return false;
  }
  ref.frames = frames;
  ref.elements = elements;
  ref.paths = header[3];
  ref.litSide.resize(elements);
  ref.radiosity.resize(frames * elements * 3);
  return readValues(in, ref.litSide.data(), elements) &&
    readValues(in, ref.radiosity.data(), ref.radiosity.size());
}

/// Writes under a temporary name and renames, so that a cache file is never half written.
void storeReference(const std::string& file, std::uint64_t key, const Reference& ref)
{
  const std::filesystem::path path(file);
  std::filesystem::create_directories(path.parent_path());
  const std::string partial = file + ".partial";
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    const std::uint64_t header[4] = { key, ref.frames, ref.elements, ref.paths };
    out.write(CacheMagic, 8);
    out.write(reinterpret_cast<const char*>(header), sizeof header);
    out.write(reinterpret_cast<const char*>(&ref.seconds), sizeof ref.seconds);
    out.write(reinterpret_cast<const char*>(ref.litSide.data()),
      static_cast<std::streamsize>(ref.litSide.size()));
    out.write(reinterpret_cast<const char*>(ref.radiosity.data()),
      static_cast<std::streamsize>(ref.radiosity.size() * sizeof(double)));
    if (!out)
    {
      throw Error("cannot write the reference cache " + partial +
        ": pass --cache DIR with a "
        "writable folder, or --cache '' to keep no cache");
    }
  }
  std::filesystem::rename(partial, path);
}

/// Classic at referenceFactor x N with its own seed, from the cache when it holds it.
Reference referenceSolution(const std::string& name, const PatchMesh& mesh, const Scene& scene,
  const LightRig& rig, const SolverOptions& base, const RigCaseOptions& caseOptions)
{
  SolverOptions o = base;
  o.pathsPerFrame = base.pathsPerFrame * static_cast<std::uint64_t>(caseOptions.referenceFactor);
  o.reuseShooting = false;
  o.reuseGathering = false;
  o.seed = ReferenceSeed;
  const std::size_t frames = frameCount(rig, scene.hasEmission());
  const std::uint64_t key = referenceKey(name, mesh, rig, o);
  Reference ref;
  if (!caseOptions.cacheDirectory.empty())
  {
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(key));
    ref.file =
      (std::filesystem::path(caseOptions.cacheDirectory) / (name + "-" + hex + ".bin")).string();
    if (loadReference(ref.file, key, frames, scene.elementCount(), ref))
    {
      ref.cached = true;
      std::printf("Reference: classic, %llu paths per frame (%dx N), seed %llu: cached in %s "
                  "(computed in %.1f s)\n",
        static_cast<unsigned long long>(ref.paths), caseOptions.referenceFactor,
        static_cast<unsigned long long>(ReferenceSeed), ref.file.c_str(), ref.seconds);
      return ref;
    }
  }
  std::printf("Reference: classic, %llu paths per frame (%dx N), seed %llu ...\n",
    static_cast<unsigned long long>(o.pathsPerFrame), caseOptions.referenceFactor,
    static_cast<unsigned long long>(ReferenceSeed));
  std::fflush(stdout);
  const Solution s = solve(scene, rig, o);
  ref.frames = frames;
  ref.elements = scene.elementCount();
  ref.paths = o.pathsPerFrame;
  ref.seconds = s.statistics.secondsTotal;
  ref.litSide.resize(ref.elements);
  ref.radiosity.resize(frames * ref.elements * 3);
  for (std::size_t e = 0; e < ref.elements; ++e)
  {
    const Side side = s.litSide(e);
    ref.litSide[e] = static_cast<std::uint8_t>(side);
    for (std::size_t f = 0; f < frames; ++f)
    {
      const Rgb b = s.total(f, e, side);
      for (int c = 0; c < 3; ++c)
      {
        ref.radiosity[(f * ref.elements + e) * 3 + static_cast<std::size_t>(c)] = b[c];
      }
    }
  }
  std::printf("           computed in %.1f s%s%s\n", ref.seconds,
    ref.file.empty() ? "" : ", cached in ", ref.file.c_str());
  if (!ref.file.empty())
  {
    storeReference(ref.file, key, ref);
  }
  return ref;
}

/// Area-weighted mean over elements and channels of (B - B_ref)^2 in `frame`, on the
/// reference's lit sides (as the paper benchmark measures).
double meanSquaredError(
  const Scene& scene, const Solution& s, const Reference& ref, std::size_t frame)
{
  double sum = 0, area = 0;
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    const Rgb b = s.total(frame, e, static_cast<Side>(ref.litSide[e]));
    double squared = 0;
    for (int c = 0; c < 3; ++c)
    {
      const double d = b[c] - ref.at(frame, e, c);
      squared += d * d;
    }
    sum += scene.elementArea(e) * squared / 3;
    area += scene.elementArea(e);
  }
  return sum / area;
}

/// The reference's area-weighted mean radiosity in `frame` (over channels): the scale of the error.
double meanRadiosity(const Scene& scene, const Reference& ref, std::size_t frame)
{
  double sum = 0, area = 0;
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    sum +=
      scene.elementArea(e) * (ref.at(frame, e, 0) + ref.at(frame, e, 1) + ref.at(frame, e, 2)) / 3;
    area += scene.elementArea(e);
  }
  return sum / area;
}

/// A solve with the process CPU seconds it took.
Solution timedSolve(
  const Scene& scene, const LightRig& rig, const SolverOptions& o, double& cpuSeconds)
{
  const double before = processCpuSeconds();
  Solution s = solve(scene, rig, o);
  cpuSeconds = processCpuSeconds() - before;
  return s;
}

struct ModeRun
{
  std::string name;
  SolverStatistics stats;
  double cpuSeconds = 0;        ///< median over the repeats
  std::vector<double> mse;      ///< at each reported frame
  double meanMse = 0;           ///< over all frames
  std::vector<double> frameMse; ///< every frame's
  int repeats = 1;
};

/// Every frame's MSE against classic's, for full reuse with the paths balanced over the
/// positions and with equal shares: the curve that chose balancing (Documentation/Method.md).
/// Printed, and returned as JSON members for report()'s extra.
std::string frameRatios(const ModeRun& classic, const ModeRun& balanced, const ModeRun& equal)
{
  std::ostringstream json;
  for (const ModeRun* m : { &balanced, &equal })
  {
    const std::vector<double>& e = m->frameMse;
    std::size_t worst = 0;
    json << ",\n    \"frame_mse_ratio_" << (m == &balanced ? "balanced" : "equal") << "\": [";
    std::printf("MSE / classic, every frame, %s:", m->name.c_str());
    for (std::size_t f = 0; f < e.size(); ++f)
    {
      const double ratio = e[f] / classic.frameMse[f];
      worst = ratio > e[worst] / classic.frameMse[worst] ? f : worst;
      std::printf(" %.2f", ratio);
      json << (f ? ", " : "") << ratio;
    }
    json << "]";
    std::printf(
      "\n  worst frame %zu: %.2f; first %.2f, middle %.2f, last %.2f; %.2f s, CPU %.2f s\n",
      worst + 1, e[worst] / classic.frameMse[worst], e.front() / classic.frameMse.front(),
      e[e.size() / 2] / classic.frameMse[e.size() / 2], e.back() / classic.frameMse.back(),
      m->stats.secondsTotal, m->cpuSeconds);
  }
  return json.str();
}

/// Solves in one mode; a solve under 3 s is timed as the median of three (same rays, same result).
ModeRun runMode(const std::string& name, const Scene& scene, const LightRig& rig, SolverOptions o,
  bool reuse, const Reference& ref, const std::vector<std::size_t>& frames)
{
  o.reuseShooting = reuse;
  o.reuseGathering = reuse;
  ModeRun run;
  run.name = name;
  std::vector<double> cpu(1);
  const Solution s = timedSolve(scene, rig, o, cpu[0]);
  std::vector<SolverStatistics> timings = { s.statistics };
  if (s.statistics.secondsTotal < 3.0)
  {
    for (int r = 0; r < 2; ++r)
    {
      cpu.emplace_back();
      timings.push_back(timedSolve(scene, rig, o, cpu.back()).statistics);
    }
    std::sort(timings.begin(), timings.end(),
      [](const SolverStatistics& a, const SolverStatistics& b)
      { return a.secondsTotal < b.secondsTotal; });
    std::sort(cpu.begin(), cpu.end());
  }
  run.stats = timings[timings.size() / 2];
  run.cpuSeconds = cpu[cpu.size() / 2];
  run.repeats = static_cast<int>(timings.size());
  for (std::size_t f : frames)
  {
    run.mse.push_back(meanSquaredError(scene, s, ref, f));
  }
  for (std::size_t f = 0; f < ref.frames; ++f)
  {
    run.frameMse.push_back(meanSquaredError(scene, s, ref, f));
    run.meanMse += run.frameMse.back() / double(ref.frames);
  }
  return run;
}

/// The table and ratios both cases print, and their JSON.
std::string report(const std::string& title, const Scene& scene, std::size_t frames,
  const SolverOptions& options, const Reference& ref, const std::vector<std::size_t>& at,
  const std::vector<std::string>& labels, const ModeRun& classic, const ModeRun& full,
  const std::string& extraJson)
{
  std::printf("\n%-12s %8s %8s %8s %8s %8s %12s %12s %12s", "mode", "total s", "s/frame", "shoot s",
    "gather s", "CPU s", "nearest-hit", "shadow", "gathering");
  for (const std::string& label : labels)
  {
    std::printf(" %14s", ("MSE " + label).c_str());
  }
  std::printf(" %14s\n", "MSE mean");
  for (const ModeRun* m : { &classic, &full })
  {
    const SolverStatistics& s = m->stats;
    std::printf("%-12s %8.2f %8.3f %8.2f %8.2f %8.2f %12llu %12llu %12llu", m->name.c_str(),
      s.secondsTotal, s.secondsTotal / double(frames), s.secondsShooting, s.secondsGathering,
      m->cpuSeconds, static_cast<unsigned long long>(s.shootingRays),
      static_cast<unsigned long long>(s.shadowRays),
      static_cast<unsigned long long>(s.gatheringRays));
    for (double e : m->mse)
    {
      std::printf(" %14.4g", e);
    }
    std::printf(" %14.4g\n", m->meanMse);
  }
  std::printf(
    "%-12s %8s %8s %8s %8s %8s %12s %12s %12s", "reference", "", "", "", "", "", "", "", "");
  for (std::size_t f : at)
  {
    char text[32];
    std::snprintf(text, sizeof text, "mean B %.3g", meanRadiosity(scene, ref, f));
    std::printf(" %14s", text);
  }
  std::printf("\n");

  const double speedup = classic.stats.secondsTotal / full.stats.secondsTotal;
  const double cpuSpeedup = classic.cpuSeconds / full.cpuSeconds;
  std::printf("\n%s: full reuse is %.2fx faster than classic (%.2f s against %.2f s; %.3f s "
              "against %.3f s per frame); %.2fx in CPU time (%.2f s against %.2f s).\n",
    title.c_str(), speedup, full.stats.secondsTotal, classic.stats.secondsTotal,
    full.stats.secondsTotal / double(frames), classic.stats.secondsTotal / double(frames),
    cpuSpeedup, full.cpuSeconds, classic.cpuSeconds);
  std::printf("MSE of full reuse / classic:");
  for (std::size_t i = 0; i < at.size(); ++i)
  {
    std::printf(
      " %s %.2f%s", labels[i].c_str(), full.mse[i] / classic.mse[i], i + 1 < at.size() ? ";" : "");
  }
  std::printf(
    "; mean over frames %.2f.\nTime x MSE gain of full reuse:", full.meanMse / classic.meanMse);
  for (std::size_t i = 0; i < at.size(); ++i)
  {
    std::printf(" %s %.1fx%s", labels[i].c_str(), speedup * classic.mse[i] / full.mse[i],
      i + 1 < at.size() ? ";" : ".\n");
  }
  std::printf("MSE in (W/m^2)^2 against the reference, on its lit sides, area-weighted; it "
              "includes the reference's own error (about 1/%d of classic's). Solves under 3 s "
              "show the median time of 3 runs. CPU s: the process's user + system seconds over all "
              "threads, which other processes on the machine hardly change.\n",
    ref.paths / options.pathsPerFrame > 0 ? int(ref.paths / options.pathsPerFrame) : 1);

  std::ostringstream json;
  json << "{\n    \"patches\": " << scene.patchCount() << ", \"elements\": " << scene.elementCount()
       << ", \"frames\": " << frames << ",\n    \"paths_per_frame\": " << options.pathsPerFrame
       << ", \"k\": " << options.gatheringRatio << ", \"lambda\": " << options.firstBounceSurvival
       << ",\n    \"reference_paths_per_frame\": " << ref.paths
       << ", \"reference_seconds\": " << ref.seconds
       << ", \"reference_cached\": " << (ref.cached ? "true" : "false")
       << ",\n    \"threads\": " << classic.stats.threads << ", \"speedup\": " << speedup
       << ", \"speedup_cpu\": " << cpuSpeedup << ",\n    \"frames_reported\": [";
  for (std::size_t i = 0; i < at.size(); ++i)
  {
    json << (i ? ", " : "") << "{\"frame\": " << at[i] + 1 << ", \"label\": \"" << labels[i]
         << "\", \"reference_mean_radiosity\": " << meanRadiosity(scene, ref, at[i]) << "}";
  }
  json << "],\n    \"modes\": [\n";
  for (const ModeRun* m : { &classic, &full })
  {
    const SolverStatistics& s = m->stats;
    json << "      {\"name\": \"" << m->name << "\", \"seconds\": " << s.secondsTotal
         << ", \"seconds_shooting\": " << s.secondsShooting
         << ", \"seconds_gathering\": " << s.secondsGathering
         << ", \"cpu_seconds\": " << m->cpuSeconds << ", \"nearest_hit_rays\": " << s.shootingRays
         << ", \"shadow_rays\": " << s.shadowRays << ", \"gathering_rays\": " << s.gatheringRays
         << ", \"mse\": [";
    for (std::size_t i = 0; i < m->mse.size(); ++i)
    {
      json << (i ? ", " : "") << m->mse[i];
    }
    json << "], \"mse_mean\": " << m->meanMse << "}" << (m == &classic ? ",\n" : "\n");
  }
  json << "    ]" << extraJson << "\n  }";
  return json.str();
}

SolverOptions paperOptions(const RigCaseOptions& c)
{
  SolverOptions o;
  o.pathsPerFrame = c.paths;
  o.threads = c.threads;
  o.gatheringRatio = c.gatheringRatio;
  o.firstBounceSurvival = 0.25;
  o.seed = 1;
  return o;
}

void checkOptions(const RigCaseOptions& c)
{
  if (c.referenceFactor < 1)
  {
    throw Error("--reference-factor must be at least 1");
  }
  if (!(c.gatheringRatio > 0 && c.gatheringRatio <= 64))
  {
    throw Error("--gathering-ratio must be above 0 and at most 64");
  }
}

// A narrow downlight as a photometric laboratory would report it: type C, rotationally
// symmetric (one horizontal angle), full intensity to 20 degrees, half at 30, dark from 50.
constexpr char SpotIes[] = "IESNA:LM-63-2002\n"
                           "[TEST] mlr-benchmark spotlight\n"
                           "[MANUFAC] MovingLightRadiosity\n"
                           "[LUMINAIRE] 30-degree spot, soft edge\n"
                           "[LAMP] 1000 lm\n"
                           "TILT=NONE\n"
                           "1 1000 1 19 1 1 2 0.05 0.05 0\n"
                           "1 1 20\n"
                           "0 5 10 15 20 25 30 35 40 45 50 55 60 65 70 75 80 85 90\n"
                           "0\n"
                           "2000 1995 1975 1940 1880 1560 1000 520 200 50 0 0 0 0 0 0 0 0 0\n";

} // namespace

std::string runTurningLight(const RigCaseOptions& c)
{
  checkOptions(c);
  if (c.frames < 2)
  {
    throw Error("the turning light needs at least 2 frames (--frames)");
  }
  const scenes::PaperRoom room = scenes::paperScaleRoom(1);
  const Scene scene = Scene::fromPatchMesh(room.mesh);
  // At the room's centre, low enough that the turned square (half side 0.575 m, so +-0.41 m
  // at 45 degrees) stays clear of the ceiling at 5.5 m.
  const Vec3 centre(2.75, 2.75, 4.8);
  const double halfTurn = 45.0 * M_PI / 180.0;
  std::vector<LightPose> poses;
  for (std::size_t k = 0; k < c.frames; ++k)
  {
    // About +y by theta from +45 to -45 degrees: the normal (-sin theta, 0, -cos theta) goes
    // from down towards -x (the red wall) to down towards +x (the green wall).
    const double theta = halfTurn - 2 * halfTurn * double(k) / double(c.frames - 1);
    LightPose pose;
    pose.position = centre;
    pose.rotation = Rotation::fromQuaternion(std::cos(theta / 2), 0, std::sin(theta / 2), 0);
    poses.push_back(pose);
  }
  LightRig rig;
  rig.areaLights.emplace_back(
    scenes::squareLightFacingDown(centre, 1.15), Rgb(100, 100, 100), poses);
  const SolverOptions options = paperOptions(c);

  std::printf("\n=== Turning light ===\nPaper-scale room: %zu patches, %zu elements; a "
              "1.15 m square light (100 W) fixed at (2.75, 2.75, 4.8) turning 90 degrees about y "
              "over %zu frames (facing 45 degrees towards -x, then towards +x); N = %llu, k = %g, "
              "lambda = %g\n",
    scene.patchCount(), scene.elementCount(), c.frames,
    static_cast<unsigned long long>(options.pathsPerFrame), options.gatheringRatio,
    options.firstBounceSurvival);
  const Reference ref = referenceSolution("turning-light", room.mesh, scene, rig, options, c);
  const std::vector<std::size_t> at = { c.frames / 2, c.frames - 1 };
  const std::vector<std::string> labels = { "frame " + std::to_string(at[0] + 1),
    "frame " + std::to_string(at[1] + 1) };
  const ModeRun classic = runMode("classic", scene, rig, options, false, ref, at);
  const ModeRun full = runMode("full reuse", scene, rig, options, true, ref, at);
  SolverOptions equalShares = options;
  equalShares.balanceFrames = false;
  const ModeRun equal = runMode("full reuse, equal shares", scene, rig, equalShares, true, ref, at);
  const std::string curves = frameRatios(classic, full, equal);
  return report("Turning light", scene, c.frames, options, ref, at, labels, classic, full, curves);
}

std::string runSunOverTown(const RigCaseOptions& c)
{
  checkOptions(c);
  const scenes::TownBlock town = scenes::townBlock();
  const Scene scene = Scene::fromPatchMesh(town.mesh);
  const SunPathRequest request = sunOverTownRequest(town);
  const std::vector<SunPosition> sun = sunPath(request);
  std::vector<Vec3> directions;
  std::size_t highest = 0;
  for (std::size_t f = 0; f < sun.size(); ++f)
  {
    if (sun[f].elevationDegrees <= 0)
    {
      throw Error("the sun benchmark expects daytime frames only");
    }
    directions.push_back(sun[f].direction);
    highest = sun[f].elevationDegrees > sun[highest].elevationDegrees ? f : highest;
  }
  LightRig rig;
  rig.directionalLights.emplace_back(directions, Rgb(1000, 1000, 1000));
  const SolverOptions options = paperOptions(c);

  auto clock = [&](std::size_t f)
  {
    const int minutes = static_cast<int>(std::lround(sun[f].clockHours * 60));
    char text[8];
    std::snprintf(text, sizeof text, "%02d:%02d", minutes / 60, minutes % 60);
    return std::string(text);
  };
  std::printf("\n=== Sun over a town block ===\nTown block: %zu buildings, %zu patches "
              "(%zu ground), %zu elements; %zu sun positions on 2024-06-21 at 48.85 N, 2.35 E, "
              "%s to %s (UTC+2) every 15 min, sun elevation %.1f, %.1f (highest, %s) and %.1f "
              "degrees; E = 1000 W/m^2; N = %llu, k = %g, lambda = %g\n",
    town.buildings.size(), scene.patchCount(), town.groundPatches, scene.elementCount(), sun.size(),
    clock(0).c_str(), clock(sun.size() - 1).c_str(), sun.front().elevationDegrees,
    sun[highest].elevationDegrees, clock(highest).c_str(), sun.back().elevationDegrees,
    static_cast<unsigned long long>(options.pathsPerFrame), options.gatheringRatio,
    options.firstBounceSurvival);
  const Reference ref = referenceSolution("sun-town", town.mesh, scene, rig, options, c);
  const std::vector<std::size_t> at = { 0, highest, sun.size() - 1 };
  const std::vector<std::string> labels = { clock(0), clock(highest), clock(sun.size() - 1) };
  const ModeRun classic = runMode("classic", scene, rig, options, false, ref, at);
  const ModeRun full = runMode("full reuse", scene, rig, options, true, ref, at);
  SolverOptions equalShares = options;
  equalShares.balanceFrames = false;
  const ModeRun equal = runMode("full reuse, equal shares", scene, rig, equalShares, true, ref, at);
  std::ostringstream extra;
  extra << frameRatios(classic, full, equal);
  extra << ",\n    \"sun_elevation_degrees\": [";
  for (std::size_t f = 0; f < sun.size(); ++f)
  {
    extra << (f ? ", " : "") << sun[f].elevationDegrees;
  }
  extra << "]";
  return report("Sun over the town block", scene, sun.size(), options, ref, at, labels, classic,
    full, extra.str());
}

std::string runPanningSpot(const RigCaseOptions& c)
{
  checkOptions(c);
  if (c.frames < 2)
  {
    throw Error("the panning spot needs at least 2 frames (--frames)");
  }
  const Luminaire spot = parseIes(SpotIes, "spotlight.ies");
  const scenes::PaperRoom room = scenes::paperScaleRoom(1);
  const Scene scene = Scene::fromPatchMesh(room.mesh);
  const Vec3 position(2.75, 2.75, 5.2);
  const double halfPan = 45.0 * M_PI / 180.0;
  std::vector<LightPose> poses;
  for (std::size_t k = 0; k < c.frames; ++k)
  {
    // About +y by theta from +45 to -45 degrees, as the turning light: the beam's axis
    // (-sin theta, 0, -cos theta) goes from the red wall (-x) over the floor to the green one.
    const double theta = halfPan - 2 * halfPan * double(k) / double(c.frames - 1);
    LightPose pose;
    pose.position = position;
    pose.rotation = Rotation::fromQuaternion(std::cos(theta / 2), 0, std::sin(theta / 2), 0);
    poses.push_back(pose);
  }
  LightRig rig;
  rig.pointLights.emplace_back(Rgb(100, 100, 100), poses, spot.distribution);
  const SolverOptions options = paperOptions(c);

  std::printf("\n=== Panning IES spot ===\nPaper-scale room: %zu patches, %zu elements; a point "
              "light (100 W) at (2.75, 2.75, 5.2) with an IES LM-63-2002 spot (half intensity at "
              "30 degrees, none from 50; %.0f lm in the file) panning 90 degrees about y over %zu "
              "frames (its axis 45 degrees towards -x, then towards +x); N = %llu, k = %g, "
              "lambda = %g\n",
    scene.patchCount(), scene.elementCount(), spot.lumens, c.frames,
    static_cast<unsigned long long>(options.pathsPerFrame), options.gatheringRatio,
    options.firstBounceSurvival);
  const Reference ref = referenceSolution("panning-spot", room.mesh, scene, rig, options, c);
  const std::vector<std::size_t> at = { 0, (c.frames - 1) / 2, c.frames - 1 };
  std::vector<std::string> labels;
  for (std::size_t f : at)
  {
    labels.push_back("frame " + std::to_string(f + 1));
  }
  const ModeRun classic = runMode("classic", scene, rig, options, false, ref, at);
  const ModeRun full = runMode("full reuse", scene, rig, options, true, ref, at);
  std::string json =
    report("Panning IES spot", scene, c.frames, options, ref, at, labels, classic, full, "");

  std::printf("ms per frame: classic %.1f, full reuse %.1f\n",
    1000 * classic.stats.secondsTotal / double(c.frames),
    1000 * full.stats.secondsTotal / double(c.frames));
  // Bare Embree's shadow rays go from surface points to the light's one position in every
  // frame, as the point light's do: a tiny square there, never translated.
  const MovingLight probe(scenes::squareLightFacingDown(position, 0.01), Rgb(1, 1, 1),
    std::vector<Vec3>(c.frames, Vec3(0, 0, 0)));
  const BareRates bare = measureBareEmbree(scene, probe, full.stats.threads, 4000000);
  const double solverShadowRate = printShadowRays(full.stats, c.frames, bare);
  std::ostringstream extra;
  extra << ",\n    \"solver_shadow_rays_per_second\": " << solverShadowRate
        << ", \"bare_shadow_rays_per_second\": " << bare.shadowRays;
  // The report's object ends in "\n  }": the rates go inside it.
  json.insert(json.size() - 4, extra.str());
  return json;
}

ReferenceRadiosity classicReference(const std::string& name, const PatchMesh& mesh,
  const Scene& scene, const LightRig& rig, const SolverOptions& base, const RigCaseOptions& options)
{
  checkOptions(options);
  Reference ref = referenceSolution(name, mesh, scene, rig, base, options);
  return { ref.paths, std::move(ref.litSide), std::move(ref.radiosity) };
}

ReferenceErrors referenceErrors(const std::string& name, const PatchMesh& mesh, const Scene& scene,
  const LightRig& rig, const SolverOptions& options, const RigCaseOptions& c,
  const std::vector<std::pair<const Solution*, std::vector<std::size_t>>>& solutions)
{
  checkOptions(c);
  const Reference ref = referenceSolution(name, mesh, scene, rig, options, c);
  ReferenceErrors out;
  out.referencePaths = ref.paths;
  out.referenceSeconds = ref.seconds;
  out.cached = ref.cached;
  for (std::size_t f = 0; f < ref.frames; ++f)
  {
    out.referenceMeanRadiosity.push_back(meanRadiosity(scene, ref, f));
  }
  for (const auto& [solution, frames] : solutions)
  {
    std::vector<double> mse;
    for (std::size_t f = 0; f < ref.frames; ++f)
    {
      double sum = 0, area = 0;
      for (std::size_t e = 0; e < scene.elementCount(); ++e)
      {
        const Rgb b = solution->total(frames[f], e, static_cast<Side>(ref.litSide[e]));
        double squared = 0;
        for (int channel = 0; channel < 3; ++channel)
        {
          const double d = b[channel] - ref.at(f, e, channel);
          squared += d * d;
        }
        sum += scene.elementArea(e) * squared / 3;
        area += scene.elementArea(e);
      }
      mse.push_back(sum / area);
    }
    out.mse.push_back(std::move(mse));
  }
  return out;
}

} // namespace mlr::bench
