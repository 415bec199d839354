// The solver's memory estimate against the bytes a solve allocates, and against the resident
// memory it takes.
//
// This executable replaces the C allocator (malloc, its aligned variants, realloc and free;
// glibc's documented way of replacing malloc) with counting wrappers around glibc's own, so
// that it sees every heap byte of the solve: operator new and so every std::vector (the
// results), std::aligned_alloc (the fixed-point accumulators) and Embree's aligned blocks
// (its BVH and buffers: about 80 bytes per element once built and 140 at the build's peak,
// measured here, against the estimate's generous 256). The counting is why this is an
// executable of its own.
#include "CoreChecks.h"
#include "FixedPointAccumulator.h"
#include "GeneratedScenes.h"
#include "MovingLight.h"
#include "Scene.h"
#include "Sensors.h"
#include "Sky.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <malloc.h>
#include <string>
#include <unistd.h>
#include <vector>

extern "C"
{
  void* __libc_malloc(std::size_t size);
  void* __libc_memalign(std::size_t alignment, std::size_t size);
  void __libc_free(void* pointer);
}

namespace
{
std::atomic<std::int64_t> liveBytes{ 0 };
std::atomic<std::int64_t> peakBytes{ 0 };

/// Every block carries, just below the pointer handed out, the block glibc gave and the
/// size asked for: the counts are the bytes requested, not glibc's rounding and alignment
/// slack (up to an alignment per block, for the accumulators' 2 MiB).
struct Header
{
  void* block;
  std::size_t size;
};
static_assert(sizeof(Header) == 16, "the header keeps malloc's 16-byte alignment");

Header* headerOf(void* pointer)
{
  return static_cast<Header*>(pointer) - 1;
}

void* counted(void* block, std::size_t offset, std::size_t size)
{
  if (!block)
  {
    return nullptr;
  }
  void* pointer = static_cast<char*>(block) + offset;
  *headerOf(pointer) = Header{ block, size };
  const auto bytes = static_cast<std::int64_t>(size);
  const std::int64_t now = liveBytes.fetch_add(bytes, std::memory_order_relaxed) + bytes;
  std::int64_t peak = peakBytes.load(std::memory_order_relaxed);
  while (now > peak && !peakBytes.compare_exchange_weak(peak, now, std::memory_order_relaxed))
  {
  }
  return pointer;
}

void* allocate(std::size_t alignment, std::size_t size)
{
  if (size > SIZE_MAX / 2)
  {
    errno = ENOMEM;
    return nullptr;
  }
  if (alignment <= sizeof(Header))
  {
    return counted(__libc_malloc(size + sizeof(Header)), sizeof(Header), size);
  }
  return counted(__libc_memalign(alignment, size + alignment), alignment, size);
}
}

extern "C"
{
  void* malloc(std::size_t size)
  {
    return allocate(0, size);
  }
  void free(void* pointer)
  {
    if (pointer)
    {
      const Header h = *headerOf(pointer);
      liveBytes.fetch_sub(static_cast<std::int64_t>(h.size), std::memory_order_relaxed);
      __libc_free(h.block);
    }
  }
  void* calloc(std::size_t count, std::size_t size)
  {
    if (size != 0 && count > SIZE_MAX / size)
    {
      errno = ENOMEM;
      return nullptr;
    }
    void* p = allocate(0, count * size);
    if (p)
    {
      std::memset(p, 0, count * size);
    }
    return p;
  }
  void* realloc(void* pointer, std::size_t size)
  {
    if (!pointer)
    {
      return malloc(size);
    }
    void* p = malloc(size);
    if (p)
    {
      std::memcpy(p, pointer, std::min(size, headerOf(pointer)->size));
      free(pointer);
    }
    return p;
  }
  void* reallocarray(void* pointer, std::size_t count, std::size_t size)
  {
    if (size != 0 && count > SIZE_MAX / size)
    {
      errno = ENOMEM;
      return nullptr;
    }
    return realloc(pointer, count * size);
  }
  std::size_t malloc_usable_size(void* pointer)
  {
    return pointer ? headerOf(pointer)->size : 0;
  }
  void* memalign(std::size_t alignment, std::size_t size)
  {
    return allocate(alignment, size);
  }
  void* aligned_alloc(std::size_t alignment, std::size_t size)
  {
    return allocate(alignment, size);
  }
  int posix_memalign(void** out, std::size_t alignment, std::size_t size)
  {
    if (alignment % sizeof(void*) != 0 || (alignment & (alignment - 1)) != 0)
    {
      return EINVAL;
    }
    void* p = allocate(alignment, size);
    if (!p)
    {
      return ENOMEM;
    }
    *out = p;
    return 0;
  }
  void* valloc(std::size_t size)
  {
    return allocate(static_cast<std::size_t>(sysconf(_SC_PAGESIZE)), size);
  }
  void* pvalloc(std::size_t size)
  {
    const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
    return allocate(page, (size + page - 1) / page * page);
  }
}

using namespace mlr;

namespace
{
/// The live heap bytes at the start of a measurement, and the peak above them since.
struct Measurement
{
  std::int64_t base = liveBytes.load();
  Measurement() { peakBytes.store(this->base); }
  std::uint64_t peak() const { return static_cast<std::uint64_t>(peakBytes.load() - this->base); }
  std::uint64_t live() const { return static_cast<std::uint64_t>(liveBytes.load() - this->base); }
};

/// A value of /proc/self/status ("VmRSS:", "VmHWM:"), in bytes.
std::uint64_t status(const char* key)
{
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
  {
    if (line.rfind(key, 0) == 0)
    {
      return std::stoull(line.substr(std::strlen(key))) * 1024;
    }
  }
  return 0;
}

/**
 * The process's resident memory, after glibc gave back the heap it holds free, and its peak
 * since, reset (clear_refs 5): what a solve takes of the machine. The solver's results are
 * mappings of their own that take memory only once written (ZeroedAllocator), which the heap
 * count above cannot see.
 */
struct Resident
{
  std::uint64_t base = 0;
  Resident()
  {
    malloc_trim(0);
    std::ofstream("/proc/self/clear_refs") << "5";
    this->base = status("VmRSS:");
    EXPECT_LE(status("VmHWM:"), this->base + (std::uint64_t(1) << 20)) << "the peak was reset";
  }
  std::uint64_t peak() const { return status("VmHWM:") - this->base; }
  std::uint64_t live() const
  {
    malloc_trim(0);
    const std::uint64_t now = status("VmRSS:");
    return now > this->base ? now - this->base : 0;
  }
};

/// A box of `cells` x `cells` per face (8: 768 patches, 3,072 elements) and a light in 1000
/// positions: the results and accumulators, proportional to frames x elements, are most of
/// the memory (tens of megabytes at 8, well above the process's own resident noise), as on
/// any scene with many frames; everything else (the tracer, per-thread scratch,
/// reachability) is about 1%.
struct ManyFrames
{
  explicit ManyFrames(int cells = 8)
    : scene(Scene::fromPatchMesh(scenes::closedBox(cells, true, { Rgb(0.5) })))
  {
  }
  Scene scene;
  MovingLight light{ scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2), Rgb(10),
    scenes::translationsAlong({ 0.5, 0.5, 0.9 }, { 0.2, 0.2, 0.9 }, { 0.8, 0.8, 0.9 }, 1000) };
};

SolverOptions optionsFor(int threads, std::uint64_t limit)
{
  SolverOptions o;
  o.pathsPerFrame = 1000; // one path per light position
  o.threads = threads;
  o.memoryLimitBytes = limit;
  return o;
}
}

TEST(SolveMemory, TheCounterSeesVectorsAndAlignedAllocations)
{
  const Measurement m;
  {
    std::vector<double> v(1000000);
    void* aligned = std::aligned_alloc(std::size_t(2) << 20, std::size_t(4) << 20);
    EXPECT_GE(m.live(), 8000000u + (4u << 20));
    std::free(aligned);
  }
  EXPECT_EQ(m.live(), 0u);
  EXPECT_GE(m.peak(), 8000000u + (4u << 20));
}

namespace
{
struct Mode
{
  const char* name;
  SolverOptions options;
};

struct Measured
{
  const char* mode = "";
  MemoryPlan plan;
  std::uint64_t peak = 0; ///< the resident peak during the solve, above what was before
  std::uint64_t held = 0; ///< what the solution holds after it
};

/// The three ways a solve keeps its accumulators, on the scene of ManyFrames: one copy per
/// worker, one copy shared by the workers, one worker.
std::vector<Measured> measureTheModes()
{
  const ManyFrames f;
  const std::size_t frames = f.light.frameCount();
  EXPECT_EQ(frames, 1000u);
  // Embree's device, TBB's threads and other once-per-process allocations come first.
  solve(f.scene,
    MovingLight(f.light.polygons(), Rgb(1), std::vector<Vec3>{ Vec3(), Vec3(0.01, 0, 0) }),
    optionsFor(2, 0));

  // The plan counts accumulators for the sides light can reach, which a solve reports.
  LightRig rig;
  rig.areaLights.push_back(f.light);
  const checks::Reached reached = checks::reachableOf(f.scene, rig, optionsFor(1, 0));
  EXPECT_EQ(static_cast<std::size_t>(std::count(reached.sides.begin(), reached.sides.end(), 1)),
    f.scene.patchCount())
    << "the inside of the box";
  const int threads = 3;
  const MemoryPlan perWorker = planSolveMemory(f.scene.patchCount(), f.scene.elementCount(),
    f.scene.points().size(), frames, optionsFor(threads, 0), 1, &reached.sides, &reached.firstHits);
  EXPECT_TRUE(perWorker.accumulatorCopyPerWorker);
  // A limit just under twice the per-worker peak leaves no room for the copies (they need it
  // to be within half the limit): the workers share one copy.
  const Mode modes[] = {
    { "one copy per worker", optionsFor(threads, 0) },
    { "one shared copy", optionsFor(threads, 2 * perWorker.peak - 1) },
    { "one worker", optionsFor(1, 0) },
  };
  std::vector<Measured> out;
  for (const Mode& mode : modes)
  {
    Measured r;
    r.mode = mode.name;
    r.plan = planSolveMemory(f.scene.patchCount(), f.scene.elementCount(), f.scene.points().size(),
      frames, mode.options, 1, &reached.sides, &reached.firstHits);
    const Resident m;
    const Solution solution = solve(f.scene, f.light, mode.options);
    r.peak = m.peak();
    r.held = m.live();
    EXPECT_EQ(solution.statistics.accumulatorCopyPerWorker, r.plan.accumulatorCopyPerWorker)
      << mode.name;
    EXPECT_EQ(solution.statistics.memoryEstimateBytes, r.plan.peak) << mode.name;
    std::printf("%s: estimate %.3f MB (results %.3f, accumulators %.3f, other %.3f); measured "
                "peak %.3f MB, results held "
                "%.3f MB; estimate / peak %.3f\n",
      mode.name, r.plan.peak / 1e6, r.plan.results / 1e6, r.plan.accumulators / 1e6,
      r.plan.other / 1e6, r.peak / 1e6, r.held / 1e6,
      static_cast<double>(r.plan.peak) / static_cast<double>(r.peak));
    out.push_back(r);
  }
  EXPECT_FALSE(out[1].plan.accumulatorCopyPerWorker) << "the shared copy was not forced";
  return out;
}
}

TEST(SolveMemory, TheEstimateBoundsThePeakAndTheResultsTightly)
{
  for (const Measured& r : measureTheModes())
  {
    const char* mode = r.mode;
    // An upper bound, and a tight one: the workers' copies of the sums make the shooting
    // peak with a copy per worker, the results the gathering one otherwise. The bound holds
    // up to the process's own resident noise (code pages first run, the threads' stacks and
    // heaps: up to 2% here). The results of the sides light cannot reach (half of them here:
    // the box's outside) are never written, and a kernel that maps no page for a read of
    // them holds none of them: the tight side allows for that. Twice the sums or the results
    // still fail it.
    const double unwritten = 0.5 * static_cast<double>(r.plan.results);
    EXPECT_LE(static_cast<double>(r.peak), 1.03 * static_cast<double>(r.plan.peak)) << mode;
    EXPECT_LE(static_cast<double>(r.plan.peak), 1.1 * static_cast<double>(r.peak) + unwritten)
      << mode;

    // After the solve the solution holds the results: direct, indirect and patch radiosity
    // (those written at least), and besides them only the lit side of the elements and the
    // statistics (in "other"). Twice the results, or a quarter, fails here.
    EXPECT_GE(static_cast<double>(r.held), static_cast<double>(r.plan.results) - unwritten) << mode;
    EXPECT_LE(
      static_cast<double>(r.held), 1.03 * static_cast<double>(r.plan.results + r.plan.other))
      << mode;
  }
}

TEST(SolveMemory, TheEstimateBoundsABatchedSolve)
{
  // Four batches of one path per position: the running mean, the squared deviations and the
  // standard errors (MemoryPlan::errorEstimate) come on top of one batch's solve, the standard
  // errors only once the last batch's accumulators are gone. Leaving them out, or counting
  // them in the shooting peak, is 11% off: the bound must hold within 10%, up to the
  // process's own resident noise (2%).
  const ManyFrames f;
  const std::size_t frames = f.light.frameCount();
  solve(f.scene,
    MovingLight(f.light.polygons(), Rgb(1), std::vector<Vec3>{ Vec3(), Vec3(0.01, 0, 0) }),
    optionsFor(2, 0));
  SolverOptions options = optionsFor(3, 0);
  options.pathsPerFrame = 4000;
  options.errorBatches = 4;
  LightRig rig;
  rig.areaLights.push_back(f.light);
  const checks::Reached reached = checks::reachableOf(f.scene, rig, options);
  const MemoryPlan plan = planSolveMemory(f.scene.patchCount(), f.scene.elementCount(),
    f.scene.points().size(), frames, options, 1, &reached.sides, &reached.firstHits);
  EXPECT_GT(plan.errorEstimate, 0u);
  const Resident m;
  const Solution solution = solve(f.scene, f.light, options);
  const std::uint64_t peak = m.peak();
  std::printf("batched: estimate %.3f MB (error estimate %.3f); measured peak %.3f MB\n",
    plan.peak / 1e6, plan.errorEstimate / 1e6, peak / 1e6);
  EXPECT_TRUE(solution.hasErrorEstimate());
  EXPECT_EQ(solution.statistics.memoryEstimateBytes, plan.peak);
  EXPECT_LE(static_cast<double>(peak), 1.02 * static_cast<double>(plan.peak));
  EXPECT_LE(static_cast<double>(plan.peak), 1.1 * static_cast<double>(peak));
}

TEST(SolveMemory, TheSensorEstimateBoundsWhatTheSensorsAllocate)
{
  // ManyFrames' 1000 light positions, with a sun and a sky that change in every frame: 300
  // sensors' three results per frame (10.8 MB) and the table of the radiosity their rays read
  // (16.8 MB, which the five walls they reach fill: a block of 546 frames) are most of it,
  // their tracer (0.8 MB estimated) and each worker's sums and shadow-ray batch over a block
  // (0.35 MB) the rest. Leaving out the tracer (or with three workers their buffers) puts the
  // estimate under the measured peak, counting it (or them) twice 5.4% (6.0%) over it: the
  // bound must hold within 5%.
  const ManyFrames f(8);
  const std::size_t frames = f.light.frameCount();
  LightRig rig;
  rig.areaLights.push_back(f.light);
  std::vector<Vec3> sun;
  std::vector<SkyFrame> sky;
  for (std::size_t k = 0; k < frames; ++k)
  {
    const double a = 0.001 * static_cast<double>(k);
    sun.push_back(normalize(Vec3(std::cos(a), std::sin(a), 1.5)));
    sky.push_back(SkyFrame{ sun.back(), 100 + a, 0, 0 });
  }
  rig.directionalLights.emplace_back(sun, Rgb(500));
  rig.skies.emplace_back(SkyModel::CieOvercast, Vec3(0, 0, 1), sky);
  SensorSet sensors;
  for (int i = 0; i < 300; ++i)
  {
    sensors.points.push_back({ 0.1 + 0.8 * (i % 20) / 20.0, 0.1 + 0.8 * (i / 20) / 15.0, 0.3 });
    sensors.normals.push_back({ 0, 0, 1 });
  }
  SensorOptions counts;
  counts.hemisphereRays = 16;
  counts.areaLightSamples = 2;
  for (int threads : { 1, 3 })
  {
    const SolverOptions options = optionsFor(threads, 0);
    const Solution solution = solve(f.scene, rig, options);
    const std::uint64_t estimate = estimateSensorMemory(sensors.size(), frames,
      f.scene.elementCount(), f.scene.points().size(), rig, false, options, counts);
    const Measurement m;
    const SensorSolution result = solveSensors(f.scene, rig, solution, sensors, options, counts);
    const std::uint64_t peak = m.peak();
    std::printf("sensors, %d threads: estimate %.3f MB, measured peak %.3f MB, held %.3f MB\n",
      threads, estimate / 1e6, peak / 1e6, m.live() / 1e6);
    EXPECT_GT(result.statistics().shadowRays, 0u);
    EXPECT_LE(peak, estimate) << threads << " threads";
    EXPECT_LE(static_cast<double>(estimate), 1.05 * static_cast<double>(peak))
      << threads << " threads";
  }
}

TEST(SolveMemory, TheSensorSpreadEstimateBoundsWhatItHolds)
{
  // ManyFrames' closed box over its 1000 frames, 300 sensors of 64 hemisphere rays read from
  // two batches: the running sums of one solve (7.2 MB), the standard errors (3.6 MB) and the
  // table of reads (all 1000 frames of the patch sides the rays reach, 12 MB, fit its
  // 16.8 MB) are most of it, the rays' element sides (0.3 MB) and the workers' sums the rest.
  // Its ray tracer, while it is made, counts as the sensors' (estimateSensorMemory). The
  // estimate's table is the 16.8 MB that rows for both sides of every patch would fill, which
  // sensors on both sides of two-sided walls reach; inside a closed box, facing up, they reach
  // the inner sides of five walls.
  const ManyFrames f(4);
  const std::size_t frames = f.light.frameCount();
  LightRig rig;
  rig.areaLights.push_back(f.light);
  SensorSet sensors;
  for (int i = 0; i < 300; ++i)
  {
    sensors.points.push_back({ 0.1 + 0.8 * (i % 20) / 20.0, 0.1 + 0.8 * (i / 20) / 15.0, 0.3 });
    sensors.normals.push_back({ 0, 0, 1 });
  }
  SensorOptions counts;
  counts.hemisphereRays = 64;
  for (int threads : { 1, 3 })
  {
    const SolverOptions options = optionsFor(threads, 0);
    const Solution solution = solve(f.scene, rig, options);
    const std::uint64_t estimate = SensorBatchSpread::estimateMemory(sensors.size(), frames, 0, 0,
                                     f.scene.patchCount(), counts, threads) +
      RayTracer::estimateMemory(f.scene.elementCount(), f.scene.points().size());
    const Measurement m;
    SensorBatchSpread spread(f.scene, sensors, options, counts, frames, 0);
    spread.add(0, 0, solution);
    spread.add(1, 0, solution);
    spread.finish();
    const std::uint64_t peak = m.peak();
    std::printf(
      "sensor spread, %d threads: estimate %.3f MB, measured peak %.3f MB, held %.3f MB\n", threads,
      estimate / 1e6, peak / 1e6, m.live() / 1e6);
    EXPECT_EQ(spread.batches(), 2u);
    EXPECT_LE(peak, estimate) << threads << " threads";
    EXPECT_LE(static_cast<double>(estimate), 1.7 * static_cast<double>(peak))
      << threads << " threads";
  }
}
