#include "LightSource.h"

#include "Error.h"
#include "RayTracer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace mlr
{

std::size_t frameCount(const LightRig& rig, bool sceneEmits)
{
  std::size_t frames = 0;
  std::string first;
  auto take = [&](std::size_t n, const std::string& what)
  {
    if (n <= 1)
    {
      return;
    }
    if (frames == 0)
    {
      frames = n;
      first = what;
    }
    else if (n != frames)
    {
      throw Error(what + " has " + std::to_string(n) + " positions but " + first + " has " +
        std::to_string(frames) + ": every moving light needs one position per frame");
    }
  };
  for (std::size_t i = 0; i < rig.areaLights.size(); ++i)
  {
    take(rig.areaLights[i].frameCount(), "light " + std::to_string(i));
  }
  for (std::size_t i = 0; i < rig.pointLights.size(); ++i)
  {
    take(rig.pointLights[i].frameCount(), "point light " + std::to_string(i));
  }
  for (std::size_t i = 0; i < rig.directionalLights.size(); ++i)
  {
    take(rig.directionalLights[i].frameCount(), "directional light " + std::to_string(i));
  }
  for (std::size_t i = 0; i < rig.skies.size(); ++i)
  {
    take(rig.skies[i].frameCount(), "sky " + std::to_string(i));
  }
  if (rig.areaLights.empty() && rig.pointLights.empty() && rig.directionalLights.empty() &&
    rig.skies.empty() && !sceneEmits)
  {
    throw Error("nothing emits light: give a light, a directional light or scene surfaces with "
                "emission");
  }
  return std::max<std::size_t>(frames, 1);
}

void KernelScratch::resize(std::size_t positions)
{
  this->kernel.resize(positions);
  this->dx.resize(positions);
  this->dy.resize(positions);
  this->dz.resize(positions);
  this->targetFrames.resize(positions);
  this->visible.resize(positions);
}

// --- Area lights -----------------------------------------------------------------------------

AreaSource::AreaSource(const MovingLight& light)
  : Light(&light)
  , Pose(12, std::vector<double>(light.frameCount(), 0.0))
{
  for (std::size_t j = 0; j < light.frameCount(); ++j)
  {
    const LightPose& pose = light.pose(j);
    const Rotation& r = pose.rotation;
    const Vec3 o = pose.position - r.apply(light.centroid());
    const double values[12] = { r.row0.x, r.row0.y, r.row0.z, r.row1.x, r.row1.y, r.row1.z,
      r.row2.x, r.row2.y, r.row2.z, o.x, o.y, o.z };
    for (int i = 0; i < 12; ++i)
    {
      this->Pose[i][j] = values[i];
    }
    this->Frames.push_back(light.photometricFrame(j));
  }
}

namespace
{
/// f_j(d / |d|) (-n_y.d) / |d|^3 for every position j, d = y - x_j, into `kernel` (0 for
/// the positions that are off or behind y), with x_j = point(j).
template <typename Point>
void distributionKernel(const IntensityDistribution& f, const PhotometricFrame* frames,
  std::size_t positions, const Point& point, const Vec3& y, const Vec3& ny, const double* on,
  double* kernel)
{
  for (std::size_t j = 0; j < positions; ++j)
  {
    const Vec3 d = y - point(j);
    const double cosY = -dot(ny, d);
    const double r2 = dot(d, d);
    double g = 0;
    if (cosY > 0 && on[j] > 0 && r2 > 0)
    {
      const double r = std::sqrt(r2);
      g = f.density(frames[j].toLocal(d / r)) * cosY / (r2 * r);
    }
    kernel[j] = g;
  }
}

/**
 * A path of light arriving from direction `towards` (unit, from the scene to the light) over
 * the bounding sphere (`centre`, `radius`): it starts on the disc of the sphere's radius
 * facing `towards`, just outside the sphere, at a uniform point, so that every point of the
 * scene sees the same density of paths (the sun's and the sky's emission).
 */
void emitFromDisc(const Vec3& centre, double radius, const Vec3& towards, double offset,
  RandomStream& random, EmittedPath& path)
{
  Vec3 t, b;
  orthonormalBasis(towards, t, b);
  // A uniform point of the disc by rejection, as sampleCosineDirection does.
  double u, v;
  do
  {
    u = 2.0 * random.uniform() - 1.0;
    v = 2.0 * random.uniform() - 1.0;
  } while (u * u + v * v >= 1.0);
  path.start = centre + towards * (radius + 2 * offset) + (t * u + b * v) * radius;
  path.direction = -towards;
  path.ownPoint = path.start;
  path.ownNormal = path.direction;
}
}

void AreaSource::emit(
  std::size_t position, RandomStream& random, double offset, EmittedPath& path) const
{
  const double u0 = random.uniform(), u1 = random.uniform(), u2 = random.uniform();
  this->Light->samplePoint(u0, u1, u2, path.ownPoint, path.ownNormal);
  const Vec3 normal = this->Light->turn(position, path.ownNormal);
  const IntensityDistribution& f = this->Light->distribution();
  if (f.isLambertian())
  {
    path.direction = sampleCosineDirection(normal, random);
    path.start = this->Light->place(position, path.ownPoint) + normal * offset;
    return;
  }
  const double v1 = random.uniform(), v2 = random.uniform();
  path.direction = this->Frames[position].toWorld(f.sample(v1, v2));
  // Off the side the path leaves from: a distribution may emit behind the light too.
  const double side = dot(path.direction, normal) < 0 ? -offset : offset;
  path.start = this->Light->place(position, path.ownPoint) + normal * side;
}

std::size_t AreaSource::kernel(const EmittedPath& path, const Vec3& y, const Vec3& ny,
  std::size_t origin, const double* on, const RayTracer& tracer, KernelScratch& scratch) const
{
  const Vec3& x = path.ownPoint;
  const Vec3& n = path.ownNormal;
  const std::size_t positions = this->positions();
  double* kernel = scratch.kernel.data();
  const double* pose[12];
  for (int i = 0; i < 12; ++i)
  {
    pose[i] = this->Pose[static_cast<std::size_t>(i)].data();
  }
  const double offset = tracer.surfaceOffset();
  std::size_t count = 0;
  const IntensityDistribution& f = this->Light->distribution();
  if (!f.isLambertian())
  {
    const MovingLight& light = *this->Light;
    distributionKernel(
      f, this->Frames.data(), positions, [&](std::size_t j) { return light.place(j, x); }, y, ny,
      on, kernel);
    const Vec3 from = tracer.liftOff(y, ny);
    for (std::size_t j = 0; j < positions; ++j)
    {
      if (kernel[j] > 0 && j != origin)
      {
        const Vec3 xj = light.place(j, x);
        const Vec3 normal = light.turn(j, n);
        const Vec3 d = xj + normal * (dot(y - xj, normal) < 0 ? -offset : offset) - from;
        scratch.dx[count] = static_cast<float>(d.x);
        scratch.dy[count] = static_cast<float>(d.y);
        scratch.dz[count] = static_cast<float>(d.z);
        scratch.targetFrames[count] = static_cast<std::uint32_t>(j);
        ++count;
      }
    }
  }
  else if (!this->Light->rotates())
  {
    // Translations only (the common case): x_j = x + o_j and n_j = n, a third of the work.
    const Vec3 toHit = y - x;
    for (std::size_t j = 0; j < positions; ++j)
    {
      const double dx = toHit.x - pose[9][j], dy = toHit.y - pose[10][j],
                   dz = toHit.z - pose[11][j];
      const double cosX = n.x * dx + n.y * dy + n.z * dz;
      const double cosY = -(ny.x * dx + ny.y * dy + ny.z * dz);
      const double r2 = dx * dx + dy * dy + dz * dz;
      const double g = cosX * cosY / std::max(r2 * r2, std::numeric_limits<double>::min());
      // Positions that are off cast no path and light nothing: their weight is never needed.
      // Tested without branches (& rather than &&), so that the loop is vectorised.
      const bool lit = (cosX > 0) & (cosY > 0) & (on[j] > 0);
      kernel[j] = lit ? g : 0.0;
    }
    // From y lifted along n_y to x_j lifted along n: o_j - (y - x) + (n - n_y) offset.
    // Every position's ray is written at the next free place and kept by counting it,
    // without a branch, through pointers the float writes cannot make the compiler reload
    // (count <= j, so the writes stay within the arrays).
    const Vec3 base = (n - ny) * offset - toHit;
    float* const outX = scratch.dx.data();
    float* const outY = scratch.dy.data();
    float* const outZ = scratch.dz.data();
    std::uint32_t* const outFrame = scratch.targetFrames.data();
    for (std::size_t j = 0; j < positions; ++j)
    {
      outX[count] = static_cast<float>(base.x + pose[9][j]);
      outY[count] = static_cast<float>(base.y + pose[10][j]);
      outZ[count] = static_cast<float>(base.z + pose[11][j]);
      outFrame[count] = static_cast<std::uint32_t>(j);
      count += static_cast<std::size_t>((kernel[j] > 0) & (j != origin));
    }
  }
  else
  {
    for (std::size_t j = 0; j < positions; ++j)
    {
      const double xj = pose[0][j] * x.x + pose[1][j] * x.y + pose[2][j] * x.z + pose[9][j];
      const double yj = pose[3][j] * x.x + pose[4][j] * x.y + pose[5][j] * x.z + pose[10][j];
      const double zj = pose[6][j] * x.x + pose[7][j] * x.y + pose[8][j] * x.z + pose[11][j];
      const double nx = pose[0][j] * n.x + pose[1][j] * n.y + pose[2][j] * n.z;
      const double nyj = pose[3][j] * n.x + pose[4][j] * n.y + pose[5][j] * n.z;
      const double nz = pose[6][j] * n.x + pose[7][j] * n.y + pose[8][j] * n.z;
      const double dx = y.x - xj, dy = y.y - yj, dz = y.z - zj;
      const double cosX = nx * dx + nyj * dy + nz * dz;
      const double cosY = -(ny.x * dx + ny.y * dy + ny.z * dz);
      const double r2 = dx * dx + dy * dy + dz * dz;
      const double g = cosX * cosY / std::max(r2 * r2, std::numeric_limits<double>::min());
      kernel[j] = cosX > 0 && cosY > 0 && on[j] > 0 ? g : 0.0;
    }
    const Vec3 from = tracer.liftOff(y, ny);
    for (std::size_t j = 0; j < positions; ++j)
    {
      if (kernel[j] > 0 && j != origin)
      {
        const Vec3 normal = this->Light->turn(j, n);
        const Vec3 d = this->Light->place(j, x) + normal * offset - from;
        scratch.dx[count] = static_cast<float>(d.x);
        scratch.dy[count] = static_cast<float>(d.y);
        scratch.dz[count] = static_cast<float>(d.z);
        scratch.targetFrames[count] = static_cast<std::uint32_t>(j);
        ++count;
      }
    }
  }
  if (count > 0)
  {
    tracer.visibleFrom(tracer.liftOff(y, ny), scratch.dx.data(), scratch.dy.data(),
      scratch.dz.data(), count, scratch.visible.data());
  }
  return count;
}

// --- Point lights ---------------------------------------------------------------------------

PointSource::PointSource(const PointLight& light)
  : Light(&light)
{
  for (std::size_t j = 0; j < light.frameCount(); ++j)
  {
    this->Frames.push_back(light.photometricFrame(j));
  }
}

void PointSource::emit(std::size_t position, RandomStream& random, double, EmittedPath& path) const
{
  const double u1 = random.uniform(), u2 = random.uniform();
  path.direction = this->Frames[position].toWorld(this->Light->distribution().sample(u1, u2));
  // A point is on no surface and occludes nothing: nothing to lift it off.
  path.start = this->Light->position(position);
  path.ownPoint = path.start;
  path.ownNormal = path.direction;
}

std::size_t PointSource::kernel(const EmittedPath&, const Vec3& y, const Vec3& ny,
  std::size_t origin, const double* on, const RayTracer& tracer, KernelScratch& scratch) const
{
  const PointLight& light = *this->Light;
  const std::size_t positions = this->positions();
  double* kernel = scratch.kernel.data();
  distributionKernel(
    light.distribution(), this->Frames.data(), positions,
    [&](std::size_t j) { return light.position(j); }, y, ny, on, kernel);
  const Vec3 from = tracer.liftOff(y, ny);
  std::size_t count = 0;
  for (std::size_t j = 0; j < positions; ++j)
  {
    if (kernel[j] > 0 && j != origin)
    {
      const Vec3 d = light.position(j) - from;
      scratch.dx[count] = static_cast<float>(d.x);
      scratch.dy[count] = static_cast<float>(d.y);
      scratch.dz[count] = static_cast<float>(d.z);
      scratch.targetFrames[count] = static_cast<std::uint32_t>(j);
      ++count;
    }
  }
  if (count > 0)
  {
    tracer.visibleFrom(
      from, scratch.dx.data(), scratch.dy.data(), scratch.dz.data(), count, scratch.visible.data());
  }
  return count;
}

// --- Directional lights ----------------------------------------------------------------------

DirectionalSource::DirectionalSource(
  const DirectionalLight& light, const Vec3& centre, double radius)
  : Light(&light)
  , Centre(centre)
  , Radius(radius)
  , Power(light.irradiance() * (M_PI * radius * radius))
  , Pose(3, std::vector<double>(light.frameCount(), 0.0))
{
  for (std::size_t j = 0; j < light.frameCount(); ++j)
  {
    const Vec3& s = light.direction(j);
    this->Pose[0][j] = s.x;
    this->Pose[1][j] = s.y;
    this->Pose[2][j] = s.z;
  }
}

BoundingDisc DirectionalSource::boundingDisc(std::size_t position, double offset) const
{
  const Vec3& s = this->Light->direction(position);
  return { this->Centre + s * (this->Radius + 2 * offset), s, this->Radius };
}

void DirectionalSource::emit(
  std::size_t position, RandomStream& random, double offset, EmittedPath& path) const
{
  emitFromDisc(this->Centre, this->Radius, this->Light->direction(position), offset, random, path);
}

std::size_t DirectionalSource::kernel(const EmittedPath&, const Vec3& y, const Vec3& ny,
  std::size_t origin, const double* on, const RayTracer& tracer, KernelScratch& scratch) const
{
  const std::size_t positions = this->positions();
  double* kernel = scratch.kernel.data();
  const double* sx = this->Pose[0].data();
  const double* sy = this->Pose[1].data();
  const double* sz = this->Pose[2].data();
  for (std::size_t j = 0; j < positions; ++j)
  {
    const double c = ny.x * sx[j] + ny.y * sy[j] + ny.z * sz[j];
    kernel[j] = c > 0 && on[j] > 0 ? c : 0.0;
  }
  std::size_t count = 0;
  for (std::size_t j = 0; j < positions; ++j)
  {
    if (kernel[j] > 0 && j != origin)
    {
      scratch.dx[count] = static_cast<float>(sx[j]);
      scratch.dy[count] = static_cast<float>(sy[j]);
      scratch.dz[count] = static_cast<float>(sz[j]);
      scratch.targetFrames[count] = static_cast<std::uint32_t>(j);
      ++count;
    }
  }
  if (count > 0)
  {
    tracer.visibleAlong(tracer.liftOff(y, ny), scratch.dx.data(), scratch.dy.data(),
      scratch.dz.data(), count, scratch.visible.data());
  }
  return count;
}

// --- Skies ----------------------------------------------------------------------------------

SkySource::SkySource(const Sky& sky, const Vec3& centre, double radius)
  : SkyRef(&sky)
  , Centre(centre)
  , Radius(radius)
{
  double largest = 0;
  for (std::size_t j = 0; j < sky.positions(); ++j)
  {
    largest = std::max(largest, sky.integral(j));
  }
  this->Power = Rgb(M_PI * radius * radius * largest);
  for (std::size_t j = 0; j < sky.positions(); ++j)
  {
    this->Factors.push_back(Rgb(largest > 0 ? sky.integral(j) / largest : 0.0));
  }
}

void SkySource::emit(
  std::size_t position, RandomStream& random, double offset, EmittedPath& path) const
{
  const double u0 = random.uniform(), u1 = random.uniform(), u2 = random.uniform();
  emitFromDisc(
    this->Centre, this->Radius, this->SkyRef->sample(position, u0, u1, u2), offset, random, path);
}

std::size_t SkySource::kernel(const EmittedPath& path, const Vec3&, const Vec3&, std::size_t,
  const double* on, const RayTracer&, KernelScratch& scratch) const
{
  // The first hit's cos(theta_y) and the disc's 1 / (pi r^2) are the same in every position
  // and cancel in the weights: the kernel is the direction density alone.
  const Sky& sky = *this->SkyRef;
  const std::size_t positions = sky.positions();
  const std::size_t cell = sky.cell(-path.direction);
  double* kernel = scratch.kernel.data();
  if (cell == Sky::Cells)
  {
    std::fill(kernel, kernel + positions, 0.0);
    return 0;
  }
  const double* density = sky.densities(cell);
  for (std::size_t j = 0; j < positions; ++j)
  {
    kernel[j] = on[j] > 0 ? density[j] : 0.0;
  }
  return 0;
}

// --- The one interface -----------------------------------------------------------------------

LightSource::LightSource(Kind kind, std::uint64_t stream, std::size_t firstFrame)
  : What(std::move(kind))
  , Stream(stream)
  , FirstFrame(firstFrame)
{
  std::visit(
    [&](const auto& light)
    {
      this->Positions = light.positions();
      this->Power = light.power();
      for (std::size_t k = 0; k < this->Positions; ++k)
      {
        this->Factors.push_back(light.factor(k));
      }
    },
    this->What);
  for (std::size_t k = 0; k < this->Positions; ++k)
  {
    const bool on = this->Factors[k].maxComponent() > 0;
    this->On.push_back(on ? 1.0 : 0.0);
    if (on)
    {
      this->Active.push_back(k);
    }
  }
}

void LightSource::emit(
  std::size_t position, RandomStream& random, double offset, EmittedPath& path) const
{
  std::visit([&](const auto& light) { light.emit(position, random, offset, path); }, this->What);
}

std::size_t LightSource::kernel(const EmittedPath& path, const Vec3& y, const Vec3& ny,
  std::size_t origin, const RayTracer& tracer, KernelScratch& scratch) const
{
  return std::visit([&](const auto& light)
    { return light.kernel(path, y, ny, origin, this->On.data(), tracer, scratch); },
    this->What);
}

std::vector<MovingLight> sceneEmitters(const Scene& scene)
{
  std::vector<MovingLight> lights;
  if (!scene.hasEmission())
  {
    return lights;
  }
  std::vector<Rgb> emissions;
  std::vector<std::vector<std::vector<Vec3>>> polygons;
  std::vector<double> areas;
  for (std::size_t p = 0; p < scene.patchCount(); ++p)
  {
    const Rgb e = scene.patchEmission(p);
    if (!(e.maxComponent() > 0))
    {
      continue;
    }
    std::size_t group = std::find(emissions.begin(), emissions.end(), e) - emissions.begin();
    if (group == emissions.size())
    {
      emissions.push_back(e);
      polygons.emplace_back();
      areas.push_back(0);
    }
    const Triangle& t = scene.patchTriangles()[p];
    const auto& points = scene.points();
    polygons[group].push_back({ points[t[0]], points[t[1]], points[t[2]] });
    areas[group] += scene.patchArea(p);
  }
  for (std::size_t g = 0; g < emissions.size(); ++g)
  {
    // One pose, moved by nothing: the emitter stays where the scene has it.
    lights.emplace_back(polygons[g], emissions[g] * areas[g], std::vector<Vec3>{ Vec3() });
  }
  return lights;
}

std::vector<LightSource> lightSources(
  const Scene& scene, const LightRig& rig, const std::vector<MovingLight>& emitters)
{
  std::vector<LightSource> sources;
  auto nextStream = [&] { return static_cast<std::uint64_t>(sources.size()) << 32; };
  for (const MovingLight& light : rig.areaLights)
  {
    sources.emplace_back(AreaSource(light), nextStream(), rig.firstFrame);
  }
  for (const MovingLight& light : emitters)
  {
    sources.emplace_back(AreaSource(light), nextStream());
  }
  for (const PointLight& light : rig.pointLights)
  {
    sources.emplace_back(PointSource(light), nextStream(), rig.firstFrame);
  }
  const Vec3 centre = (scene.boundsMin() + scene.boundsMax()) * 0.5;
  const double radius = std::max(0.5 * scene.diagonal(), 1e-9 * std::max(1.0, length(centre)));
  for (const DirectionalLight& light : rig.directionalLights)
  {
    sources.emplace_back(DirectionalSource(light, centre, radius), nextStream(), rig.firstFrame);
  }
  for (const Sky& sky : rig.skies)
  {
    sources.emplace_back(SkySource(sky, centre, radius), nextStream(), rig.firstFrame);
  }
  return sources;
}

} // namespace mlr
