#include "Sky.h"

#include "Error.h"
#include "Parallel.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mlr
{

SkyModel parseSkyModel(const std::string& name)
{
  if (name == "uniform")
  {
    return SkyModel::Uniform;
  }
  if (name == "cie-overcast")
  {
    return SkyModel::CieOvercast;
  }
  if (name == "cie-clear")
  {
    return SkyModel::CieClear;
  }
  if (name == "perez")
  {
    return SkyModel::Perez;
  }
  throw Error("the sky model is '" + name + "': give uniform, cie-overcast, cie-clear or perez");
}

std::string skyModelName(SkyModel model)
{
  switch (model)
  {
    case SkyModel::Uniform:
      return "uniform";
    case SkyModel::CieOvercast:
      return "cie-overcast";
    case SkyModel::CieClear:
      return "cie-clear";
    case SkyModel::Perez:
      break;
  }
  return "perez";
}

namespace
{
/// Perez et al. (1993), table 1: for each sky clearness bin, a1..a4, b1..b4, c1..c4, d1..d4,
/// e1..e4 (the values gendaylit uses).
constexpr double PerezTable[8][20] = {
  { 1.3525, -0.2576, -0.2690, -1.4366, -0.7670, 0.0007, 1.2734, -0.1233, 2.8000, 0.6004, 1.2375,
    1.0000, 1.8734, 0.6297, 0.9738, 0.2809, 0.0356, -0.1246, -0.5718, 0.9938 },
  { -1.2219, -0.7730, 1.4148, 1.1016, -0.2054, 0.0367, -3.9128, 0.9156, 6.9750, 0.1774, 6.4477,
    -0.1239, -1.5798, -0.5081, -1.7812, 0.1080, 0.2624, 0.0672, -0.2190, -0.4285 },
  { -1.1000, -0.2515, 0.8952, 0.0156, 0.2782, -0.1812, -4.5000, 1.1766, 24.7219, -13.0812, -37.7000,
    34.8438, -5.0000, 1.5218, 3.9229, -2.6204, -0.0156, 0.1597, 0.4199, -0.5562 },
  { -0.5484, -0.6654, -0.2672, 0.7117, 0.7234, -0.6219, -5.6812, 2.6297, 33.3389, -18.3000,
    -62.2500, 52.0781, -3.5000, 0.0016, 1.1477, 0.1062, 0.4659, -0.3296, -0.0876, -0.0329 },
  { -0.6000, -0.3566, -2.5000, 2.3250, 0.2937, 0.0496, -5.6812, 1.8415, 21.0000, -4.7656, -21.5906,
    7.2492, -3.5000, -0.1554, 1.4062, 0.3988, 0.0032, 0.0766, -0.0656, -0.1294 },
  { -1.0156, -0.3670, 1.0078, 1.4051, 0.2875, -0.5328, -3.8500, 3.3750, 14.0000, -0.9999, -7.1406,
    7.5469, -3.4000, -0.1078, -1.0750, 1.5702, -0.0672, 0.4016, 0.3017, -0.4844 },
  { -1.0000, 0.0211, 0.5025, -0.5119, -0.3000, 0.1922, 0.7023, -1.6317, 19.0000, -5.0000, 1.2438,
    -1.9094, -4.0000, 0.0250, 0.3844, 0.2656, 1.0468, -0.3788, -2.4517, 1.4656 },
  { -1.0500, 0.0289, 0.4260, 0.3590, -0.3250, 0.1156, 0.7781, 0.0025, 31.0625, -14.5000, -46.1148,
    55.3750, -7.2312, 0.4050, 13.3500, 0.6234, 1.5000, -0.6426, 1.8564, 0.5636 },
};
constexpr double ClearnessBounds[8] = { 1.000, 1.065, 1.230, 1.500, 1.950, 2.800, 4.500, 6.200 };

int clearnessBin(double epsilon)
{
  int bin = 0;
  while (bin < 7 && epsilon >= ClearnessBounds[bin + 1])
  {
    ++bin;
  }
  return bin;
}

/// The sun's zenith angle (radians) for the Perez formulas, which hold from zenith to horizon.
double perezSunZenith(const Vec3& sunLocal)
{
  return std::acos(std::clamp(sunLocal.z, 0.0, 1.0));
}

/// The top of the clearness range the model was fitted on.
constexpr double MaxClearness = 12;

/// The day gendaylit assumes when it is given none.
constexpr int DefaultDayOfYear = 150;

/// Sky clearness epsilon and brightness Delta (Perez 1990) of E_dh and E_dn at sun zenith Z
/// on a day of the year (0: not known), clamped to the ranges the model was fitted on
/// (gendaylit refuses values outside them).
void perezIndices(
  double diffuse, double direct, double Z, int dayOfYear, double& epsilon, double& delta)
{
  if (!(diffuse > 0))
  {
    // Direct light and no diffuse light is the clearest sky (gendaylit's division gives
    // infinity, then clamped), not an overcast one.
    epsilon = direct > 0 ? MaxClearness : 1;
    delta = 0.01;
    return;
  }
  const double z3 = 1.041 * Z * Z * Z;
  epsilon = ((diffuse + std::max(direct, 0.0)) / diffuse + z3) / (1 + z3);
  const double zenithDegrees = Z * 180 / M_PI;
  const double airMass = 1.0 / (std::cos(Z) + 0.15 * std::pow(93.885 - zenithDegrees, -1.253));
  // The extraterrestrial irradiance varies by 3.3 % either way over the year with the
  // Earth-sun distance.
  const int day = dayOfYear > 0 ? dayOfYear : DefaultDayOfYear;
  const double dayAngle = 2 * M_PI * (day - 1) / 365.0;
  const double eccentricity = 1.00011 + 0.034221 * std::cos(dayAngle) +
    0.00128 * std::sin(dayAngle) + 0.000719 * std::cos(2 * dayAngle) +
    0.000077 * std::sin(2 * dayAngle);
  delta = diffuse * airMass / (1367.0 * eccentricity);
  epsilon = std::clamp(epsilon, 1.0, MaxClearness);
  delta = std::clamp(delta, 0.01, 0.6);
}

constexpr double PrecipitableWater = 2.0; // cm

/// cos t at 6 degrees of elevation, the lowest at which Radiance evaluates the Perez model:
/// gendaylit normalises the sky on the centres of the 145 Tregenza patches, whose lowest ring
/// is there, and gendaymtx's default sky takes each patch's value at its centre.
const double LowestEvaluatedCosine = std::sin(6 * M_PI / 180);
}

SkyDistribution::SkyDistribution(
  SkyModel model, const Vec3& sun, double diffuseHorizontal, double directNormal, int dayOfYear)
  : Model(model)
  , Sun(normalize(sun))
{
  if (model != SkyModel::Perez)
  {
    return;
  }
  const double Z = perezSunZenith(this->Sun);
  double epsilon, delta;
  perezIndices(diffuseHorizontal, directNormal, Z, dayOfYear, epsilon, delta);
  this->Clearness = epsilon;
  this->Brightness = delta;
  if (epsilon > 1.065 && epsilon < 2.8)
  {
    delta = std::max(delta, 0.2);
  }
  const int bin = clearnessBin(epsilon);
  const double* x = PerezTable[bin];
  for (int i = 0; i < 5; ++i)
  {
    this->Coefficients[i] = x[4 * i] + x[4 * i + 1] * Z + delta * (x[4 * i + 2] + x[4 * i + 3] * Z);
  }
  if (bin == 0)
  {
    this->Coefficients[2] = std::exp(std::pow(delta * (x[8] + x[9] * Z), x[10])) - x[11];
    this->Coefficients[3] = -std::exp(delta * (x[12] + x[13] * Z)) + x[14] + delta * x[15];
  }
}

double SkyDistribution::gradation(double z) const
{
  const double cosZ = std::max(z, 0.0);
  switch (this->Model)
  {
    case SkyModel::Uniform:
    case SkyModel::CieOvercast:
      return 1.0;
    case SkyModel::CieClear:
      return cosZ > 0 ? 1.0 - std::exp(-0.32 / cosZ) : 1.0;
    case SkyModel::Perez:
      break;
  }
  const double* k = this->Coefficients;
  // With b > 0, a e^(b / cos t) grows without bound towards the horizon (e^97 in the table's
  // lowest ring at b = 0.3): normalised to E_dh, most of the sky's light lay in the last 1.5
  // degrees and a wall facing away from a sun at 1 degree got ten times E_dh. Radiance
  // evaluates no such sky below 6 degrees (gendaylit writes a dark error sky for b > 0), so below
  // there the gradation keeps its value at 6 degrees. With b <= 0 it tends to 1 on its own, as
  // perezlum.cal renders it.
  const double c = k[1] > 0 ? std::max(cosZ, LowestEvaluatedCosine) : cosZ;
  return c > 0 ? 1.0 + k[0] * std::exp(k[1] / c) : 1.0;
}

double SkyDistribution::operator()(const Vec3& v, double gradation) const
{
  const double cosZ = std::max(v.z, 0.0);
  switch (this->Model)
  {
    case SkyModel::Uniform:
      return 1.0;
    case SkyModel::CieOvercast:
      return 1.0 + 2.0 * cosZ;
    case SkyModel::CieClear:
    {
      // cos chi is the dot product itself: std::cos of the angle took a third of a year's
      // tables.
      const double c = std::clamp(dot(v, this->Sun), -1.0, 1.0);
      const double chi = std::acos(c);
      const double indicatrix =
        1.0 + 10.0 * (std::exp(-3.0 * chi) - std::exp(-3.0 * M_PI / 2)) + 0.45 * c * c;
      return gradation * indicatrix;
    }
    case SkyModel::Perez:
      break;
  }
  const double* k = this->Coefficients;
  const double c = std::clamp(dot(v, this->Sun), -1.0, 1.0);
  const double gamma = std::acos(c);
  // Negative only where the fit extrapolates badly: no light there.
  return std::max(0.0, gradation * (1.0 + k[2] * std::exp(k[3] * gamma) + k[4] * c * c));
}

DaylightEfficacy perezEfficacy(const SkyFrame& frame, const Vec3& up)
{
  const double Z = perezSunZenith({ 0, 0, dot(normalize(frame.sun), normalize(up)) });
  double epsilon, delta;
  perezIndices(frame.diffuseHorizontal, frame.directNormal, Z, frame.dayOfYear, epsilon, delta);
  const int bin = clearnessBin(epsilon);
  static constexpr double da[8] = { 97.24, 107.22, 104.97, 102.39, 100.71, 106.42, 141.88, 152.23 };
  static constexpr double db[8] = { -0.46, 1.15, 2.96, 5.59, 5.94, 3.83, 1.90, 0.35 };
  static constexpr double dc[8] = { 12.00, 0.59, -5.53, -13.95, -22.75, -36.15, -53.24, -45.27 };
  static constexpr double dd[8] = { -8.91, -3.95, -8.77, -13.90, -23.74, -28.83, -14.03, -7.98 };
  static constexpr double sa[8] = { 57.20, 98.99, 109.83, 110.34, 106.36, 107.19, 105.75, 101.18 };
  static constexpr double sb[8] = { -4.55, -3.46, -4.90, -5.84, -3.97, -1.25, 0.77, 1.58 };
  static constexpr double sc[8] = { -2.98, -1.21, -1.71, -1.99, -1.75, -1.51, -1.26, -1.10 };
  static constexpr double sd[8] = { 117.12, 12.38, -8.81, -4.56, -6.16, -26.73, -34.44, -8.29 };
  DaylightEfficacy e;
  e.diffuse =
    da[bin] + db[bin] * PrecipitableWater + dc[bin] * std::cos(Z) + dd[bin] * std::log(delta);
  e.direct = std::max(0.0,
    sa[bin] + sb[bin] * PrecipitableWater + sc[bin] * std::exp(5.73 * Z - 5) + sd[bin] * delta);
  return e;
}

namespace
{
constexpr double RingStep = M_PI / 2 / Sky::Rings;
constexpr double SectorStep = 2 * M_PI / Sky::Sectors;
constexpr int SubSamples = 4;

bool sameSky(SkyModel model, const SkyFrame& a, const SkyFrame& b)
{
  if (a.diffuseHorizontal != b.diffuseHorizontal)
  {
    return false;
  }
  if (model == SkyModel::Uniform || model == SkyModel::CieOvercast)
  {
    return true;
  }
  return a.sun.x == b.sun.x && a.sun.y == b.sun.y && a.sun.z == b.sun.z &&
    (model != SkyModel::Perez || (a.directNormal == b.directNormal && a.dayOfYear == b.dayOfYear));
}

/// The subsamples' directions, the same for every position: cos and sin of each azimuth, and
/// the cosine and sine of each zenith angle.
struct CellDirections
{
  std::vector<double> cosPhi, sinPhi, ringCos, ringSin;

  CellDirections()
    : cosPhi(std::size_t(Sky::Sectors) * SubSamples)
    , sinPhi(std::size_t(Sky::Sectors) * SubSamples)
    , ringCos(std::size_t(Sky::Rings) * SubSamples)
    , ringSin(std::size_t(Sky::Rings) * SubSamples)
  {
    for (int s = 0; s < Sky::Sectors; ++s)
    {
      for (int j = 0; j < SubSamples; ++j)
      {
        const double phi = (s + (j + 0.5) / SubSamples) * SectorStep;
        this->cosPhi[std::size_t(s) * SubSamples + j] = std::cos(phi);
        this->sinPhi[std::size_t(s) * SubSamples + j] = std::sin(phi);
      }
    }
    for (int r = 0; r < Sky::Rings; ++r)
    {
      const double c0 = std::cos(r * RingStep), c1 = std::cos((r + 1) * RingStep);
      for (int i = 0; i < SubSamples; ++i)
      {
        const double cz = c0 + (c1 - c0) * (i + 0.5) / SubSamples;
        this->ringCos[std::size_t(r) * SubSamples + i] = cz;
        this->ringSin[std::size_t(r) * SubSamples + i] = std::sqrt(std::max(0.0, 1 - cz * cz));
      }
    }
  }
};

/// Each cell's mean of `f` into `mean`, and the sky's integrals over the horizontal (cosine
/// weighted) and over the solid angle.
void tabulate(const SkyDistribution& f, const CellDirections& d, std::vector<double>& mean,
  double& horizontal, double& total)
{
  horizontal = total = 0;
  double gradation[SubSamples];
  for (int r = 0; r < Sky::Rings; ++r)
  {
    const double c0 = std::cos(r * RingStep), c1 = std::cos((r + 1) * RingStep);
    const double solidAngle = SectorStep * (c0 - c1);
    const double cosine = SectorStep * (c0 * c0 - c1 * c1) / 2;
    const double* cz = d.ringCos.data() + std::size_t(r) * SubSamples;
    const double* sz = d.ringSin.data() + std::size_t(r) * SubSamples;
    for (int i = 0; i < SubSamples; ++i)
    {
      gradation[i] = f.gradation(cz[i]);
    }
    for (int s = 0; s < Sky::Sectors; ++s)
    {
      // The cell's mean by the midpoint rule in cos(theta) and phi, which is uniform in
      // solid angle: the paths draw directions uniformly within the cell.
      double sum = 0;
      const double* cp = d.cosPhi.data() + std::size_t(s) * SubSamples;
      const double* sp = d.sinPhi.data() + std::size_t(s) * SubSamples;
      for (int i = 0; i < SubSamples; ++i)
      {
        for (int j = 0; j < SubSamples; ++j)
        {
          sum += f({ sz[i] * cp[j], sz[i] * sp[j], cz[i] }, gradation[i]);
        }
      }
      const double m = sum / (SubSamples * SubSamples);
      mean[std::size_t(r) * Sky::Sectors + s] = m;
      horizontal += m * cosine;
      total += m * solidAngle;
    }
  }
}
}

Sky Sky::slice(std::size_t first, std::size_t count) const
{
  if (this->Frames.size() == 1)
  {
    return Sky(this->Model, this->Up, std::vector<SkyFrame>(count, this->Frames.front()));
  }
  return Sky(this->Model, this->Up,
    std::vector<SkyFrame>(this->Frames.begin() + first, this->Frames.begin() + first + count));
}

Sky::Sky(SkyModel model, const Vec3& up, const std::vector<SkyFrame>& frames, int threads)
  : Model(model)
  , FrameCount(frames.size())
{
  if (frames.empty())
  {
    throw Error("the sky has no frames");
  }
  if (!(length(up) > 0) || !std::isfinite(length(up)))
  {
    throw Error("the up direction is zero or not finite: give the zenith as X,Y,Z");
  }
  this->Up = normalize(up);
  orthonormalBasis(this->Up, this->T, this->B);
  for (std::size_t f = 0; f < frames.size(); ++f)
  {
    const double e = frames[f].diffuseHorizontal;
    if (!(e >= 0) || !std::isfinite(e))
    {
      std::ostringstream s;
      s << "the sky's diffuse horizontal irradiance of frame " << f << " is " << e
        << ": give W/m^2, 0 or above";
      throw Error(s.str());
    }
    if (model == SkyModel::Perez &&
      !(frames[f].directNormal >= 0 && std::isfinite(frames[f].directNormal)))
    {
      std::ostringstream s;
      s << "the direct normal irradiance of frame " << f << " is " << frames[f].directNormal
        << ": give W/m^2, 0 or above";
      throw Error(s.str());
    }
    if (frames[f].dayOfYear < 0 || frames[f].dayOfYear > 366)
    {
      throw Error("the day of the year of frame " + std::to_string(f) + " is " +
        std::to_string(frames[f].dayOfYear) + ": give 1 to 366, or 0 when the date is not known");
    }
    if ((model == SkyModel::CieClear || model == SkyModel::Perez) && !(length(frames[f].sun) > 0))
    {
      throw Error("the sun direction of frame " + std::to_string(f) + " is zero");
    }
  }
  bool constant = true;
  for (const SkyFrame& frame : frames)
  {
    constant = constant && sameSky(model, frame, frames.front());
  }
  this->Frames = constant ? std::vector<SkyFrame>{ frames.front() } : frames;
  const std::size_t positions = this->Frames.size();
  this->Density.assign(Cells * positions, 0.0);
  this->Cdf.assign(Cells * positions, 0.0);
  this->Scale.assign(positions, 0.0);
  this->Lambda.assign(positions, 0.0);
  // Each position is tabulated alone, into its own entries: the bits do not depend on the
  // workers. A dark sky is reported for the first such frame after the loop, whichever
  // worker found it.
  std::vector<std::uint8_t> dark(positions, 0);
  const int workers = resolveThreadCount(threads);
  std::vector<std::vector<double>> means(static_cast<std::size_t>(workers));
  const CellDirections directions;
  this->UniformInstead.assign(positions, 0);
  parallelFor(
    positions, workers,
    [&](std::size_t k, int worker)
    {
      std::vector<double>& mean = means[static_cast<std::size_t>(worker)];
      mean.resize(Cells);
      const SkyFrame& frame = this->Frames[k];
      double horizontal = 0, total = 0;
      tabulate(this->distribution(k), directions, mean, horizontal, total);
      // A uniform sky of relative luminance 1 gives pi: a Perez sky left with a thousandth
      // of that is negative but for a sliver, which normalised to E_dh would blaze.
      constexpr double Sliver = 1e-3 * M_PI;
      if (!(horizontal > Sliver) && model == SkyModel::Perez)
      {
        // The Perez fit is negative over (nearly) the whole sky (a high sun, little diffuse
        // light and two to three times as much direct): Radiance's gendaymtx draws such an
        // hour as a uniform sky, and so does this table, rather than stop a weather year there.
        this->UniformInstead[k] = 1;
        tabulate(this->distribution(k), directions, mean, horizontal, total);
      }
      if (!(horizontal > 0))
      {
        dark[k] = 1;
        return;
      }
      const double scale = frame.diffuseHorizontal / horizontal;
      this->Scale[k] = scale;
      this->Lambda[k] = scale * total;
      double cumulative = 0;
      for (int r = 0; r < Rings; ++r)
      {
        const double solidAngle =
          SectorStep * (std::cos(r * RingStep) - std::cos((r + 1) * RingStep));
        for (int s = 0; s < Sectors; ++s)
        {
          const std::size_t c = std::size_t(r) * Sectors + s;
          this->Density[c * positions + k] = mean[c] / total;
          cumulative += mean[c] * solidAngle / total;
          this->Cdf[k * Cells + c] = cumulative;
        }
      }
      this->Cdf[k * Cells + Cells - 1] = 1.0;
    },
    [](std::size_t) { return true; });
  for (std::size_t k = 0; k < positions; ++k)
  {
    if (dark[k])
    {
      throw Error("the " + skyModelName(model) + " sky of frame " + std::to_string(k) +
        " is dark everywhere: check its sun direction and irradiances");
    }
  }
}

std::uint64_t Sky::allocatedBytes() const
{
  return (this->Density.size() + this->Cdf.size() + this->Lambda.size() + this->Scale.size()) *
    sizeof(double) +
    this->Frames.size() * sizeof(SkyFrame);
}

std::size_t Sky::cell(const Vec3& towardsSky) const
{
  const Vec3 v = this->toLocal(towardsSky);
  if (!(v.z > 0))
  {
    return Cells;
  }
  const double theta = std::acos(std::min(v.z, 1.0));
  double phi = std::atan2(v.y, v.x);
  if (phi < 0)
  {
    phi += 2 * M_PI;
  }
  const int r = std::min(static_cast<int>(theta / RingStep), Rings - 1);
  const int s = std::min(static_cast<int>(phi / SectorStep), Sectors - 1);
  return std::size_t(r) * Sectors + s;
}

double Sky::radiance(std::size_t position, const Vec3& towardsSky) const
{
  const std::size_t c = this->cell(towardsSky);
  return c == Cells ? 0.0 : this->density(position, c) * this->Lambda[position];
}

SkyDistribution Sky::distribution(std::size_t position) const
{
  const SkyFrame& frame = this->Frames[position];
  return SkyDistribution(this->UniformInstead[position] ? SkyModel::Uniform : this->Model,
    this->toLocal(normalize(frame.sun)), frame.diffuseHorizontal, frame.directNormal,
    frame.dayOfYear);
}

std::vector<std::size_t> Sky::uniformInsteadFrames() const
{
  std::vector<std::size_t> frames;
  for (std::size_t k = 0; k < this->UniformInstead.size(); ++k)
  {
    if (this->UniformInstead[k])
    {
      frames.push_back(k);
    }
  }
  return frames;
}

double Sky::modelRadiance(std::size_t position, const Vec3& towardsSky) const
{
  const Vec3 v = this->toLocal(normalize(towardsSky));
  if (!(v.z > 0))
  {
    return 0;
  }
  return this->Scale[position] * this->distribution(position)(v);
}

Vec3 Sky::sample(std::size_t position, double u0, double u1, double u2) const
{
  const double* cdf = this->Cdf.data() + position * Cells;
  const std::size_t c =
    std::min<std::size_t>(std::upper_bound(cdf, cdf + Cells, u0) - cdf, Cells - 1);
  const int r = static_cast<int>(c / Sectors), s = static_cast<int>(c % Sectors);
  const double c0 = std::cos(r * RingStep), c1 = std::cos((r + 1) * RingStep);
  const double cz = c0 + (c1 - c0) * u1;
  const double sz = std::sqrt(std::max(0.0, 1 - cz * cz));
  const double phi = (s + u2) * SectorStep;
  return this->T * (sz * std::cos(phi)) + this->B * (sz * std::sin(phi)) + this->Up * cz;
}

} // namespace mlr
