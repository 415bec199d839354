// Luminous intensity distributions and the photometric files: each kind's density integrates
// to 1, sample() draws from density() (a chi-square bound on a histogram, fixed seeds), the
// IES and EULUMDAT readers give the flux of the distribution they describe, their symmetric
// forms equal the full table, C = 90 lies towards +y, types B and A follow their own axes, the
// TILT=INCLUDE table and the luminous opening's shape are read, and bad files (malformed TILT
// blocks among them) are refused with the line and field to fix.
#include "CoreChecks.h"
#include "Photometry.h"
#include "Random.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>

using namespace mlr;

namespace
{
constexpr double Pi = 3.14159265358979323846;

Vec3 direction(double gamma, double c)
{
  return Vec3(std::sin(gamma) * std::cos(c), std::sin(gamma) * std::sin(c), std::cos(gamma));
}

/// The integral of density() over the sphere: midpoints in cos(gamma) and C.
double sphereIntegral(const IntensityDistribution& d, int nz = 2000, int nc = 360)
{
  double sum = 0;
  for (int i = 0; i < nz; ++i)
  {
    const double z = -1 + (i + 0.5) * 2.0 / nz;
    for (int j = 0; j < nc; ++j)
    {
      sum += d.density(direction(std::acos(z), (j + 0.5) * 2 * Pi / nc));
    }
  }
  return sum * (2.0 / nz) * (2 * Pi / nc);
}

/// A rotationally symmetric density's integral: 2 pi times a fine midpoint rule in gamma.
double axialIntegral(const IntensityDistribution& d)
{
  const int n = 200000;
  double sum = 0;
  for (int i = 0; i < n; ++i)
  {
    const double g = (i + 0.5) * Pi / n;
    sum += d.density(direction(g, 0.3)) * std::sin(g);
  }
  return sum * 2 * Pi * Pi / n;
}

/// A table's distribution from f(gamma, C) at the given angles (radians).
IntensityDistribution table(const std::vector<double>& gammas, const std::vector<double>& planes,
  const std::function<double(double, double)>& f)
{
  std::vector<double> candela;
  for (double c : planes)
  {
    for (double g : gammas)
    {
      candela.push_back(f(g, c));
    }
  }
  return IntensityDistribution::tabulated(gammas, planes, candela);
}

std::vector<double> degrees(double first, double last, double step)
{
  std::vector<double> angles;
  for (int i = 0; first + i * step <= last + 1e-9; ++i)
  {
    angles.push_back(first + i * step);
  }
  return angles;
}

std::vector<double> radians(const std::vector<double>& angles)
{
  std::vector<double> out;
  for (double a : angles)
  {
    out.push_back(a * Pi / 180);
  }
  return out;
}

/**
 * Draws `n` directions and compares their histogram over bins of cos(gamma) in [zLow, 1] and
 * C with the expected counts from density(). Bins expecting fewer than 5 are merged into one.
 * The statistic of a correct sampler has mean dof and deviation sqrt(2 dof); the bound is five
 * deviations above. No direction may fall where the density is 0.
 */
void expectSamplesFollowDensity(const IntensityDistribution& d, double zLow, std::uint64_t key)
{
  const int nz = 16, nc = 12, n = 200000, sub = 24;
  std::vector<double> expected(nz * nc, 0), observed(nz * nc, 0);
  const double dz = (1 - zLow) / nz, dc = 2 * Pi / nc;
  for (int a = 0; a < nz; ++a)
  {
    for (int b = 0; b < nc; ++b)
    {
      double sum = 0;
      for (int i = 0; i < sub; ++i)
      {
        for (int j = 0; j < sub; ++j)
        {
          const double z = zLow + (a + (i + 0.5) / sub) * dz;
          sum += d.density(direction(std::acos(z), (b + (j + 0.5) / sub) * dc));
        }
      }
      expected[a * nc + b] = sum * dz * dc / (sub * sub) * n;
    }
  }
  RandomStream random(20261201, StreamPurpose::Shooting, key);
  int outside = 0, zeroDensity = 0;
  for (int k = 0; k < n; ++k)
  {
    const double u1 = random.uniform(), u2 = random.uniform();
    const Vec3 v = d.sample(u1, u2);
    ASSERT_NEAR(length(v), 1, 1e-12);
    zeroDensity += d.density(v) > 0 ? 0 : 1;
    if (v.z < zLow)
    {
      ++outside;
      continue;
    }
    double c = std::atan2(v.y, v.x);
    c += c < 0 ? 2 * Pi : 0;
    const int a = std::min(nz - 1, static_cast<int>((v.z - zLow) / dz));
    const int b = std::min(nc - 1, static_cast<int>(c / dc));
    observed[a * nc + b] += 1;
  }
  EXPECT_EQ(zeroDensity, 0);
  double chi = 0, restExpected = n, restObserved = n - outside;
  int dof = 0;
  for (std::size_t i = 0; i < expected.size(); ++i)
  {
    if (expected[i] >= 5)
    {
      chi += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
      restExpected -= expected[i];
      restObserved -= observed[i];
      ++dof;
    }
  }
  // The bins below zLow and the sparse bins, together.
  if (restExpected >= 5)
  {
    chi += (restObserved + outside - restExpected) * (restObserved + outside - restExpected) /
      restExpected;
    ++dof;
  }
  else
  {
    EXPECT_LE(restObserved + outside, 5 + 5 * std::sqrt(5.0));
  }
  ASSERT_GT(dof, 20) << "too few bins to test";
  EXPECT_LT(chi, dof + 5 * std::sqrt(2.0 * dof)) << "dof " << dof << ", key " << key;
}

/// A directory of its own under the system's temporary directory, removed at the end.
struct TemporaryDirectory
{
  std::filesystem::path path;
  TemporaryDirectory()
  {
    std::string pattern =
      (std::filesystem::temp_directory_path() / "mlr-photometry-XXXXXX").string();
    if (!mkdtemp(pattern.data()))
    {
      throw std::runtime_error("cannot create a temporary directory");
    }
    this->path = pattern;
  }
  ~TemporaryDirectory() { std::filesystem::remove_all(this->path); }

  std::string write(const std::string& name, const std::string& text) const
  {
    const std::string file = (this->path / name).string();
    std::ofstream(file, std::ios::binary) << text;
    return file;
  }
};

std::string join(const std::vector<double>& values, const char* separator = " ")
{
  std::ostringstream s;
  s.precision(17);
  for (std::size_t i = 0; i < values.size(); ++i)
  {
    s << (i ? separator : "") << values[i];
  }
  return s.str();
}

/// An LM-63-2002 file of f(gamma, C) (degrees) at the given angles. Its lines: 1 the edition,
/// 2 a keyword, 3 TILT, 4 the lamp line, 5 the ballast line, 6 vertical angles, 7 horizontal
/// angles, 8 on the candela, a plane a line.
std::string iesFile(const std::vector<double>& vertical, const std::vector<double>& horizontal,
  const std::function<double(double, double)>& f, double multiplier = 1, double ballast = 1,
  const std::string& tilt = "TILT=NONE")
{
  std::ostringstream s;
  s.precision(17);
  s << "IESNA:LM-63-2002\n[TEST] generated by TestPhotometry\n" << tilt << "\n";
  s << "1 -1 " << multiplier << " " << vertical.size() << " " << horizontal.size()
    << " 1 2 0.6 1.2 0\n";
  s << ballast << " 1 40\n" << join(vertical) << "\n" << join(horizontal) << "\n";
  for (double h : horizontal)
  {
    std::vector<double> row;
    for (double v : vertical)
    {
      row.push_back(f(v, h));
    }
    s << join(row) << "\n";
  }
  return s.str();
}

/// A EULUMDAT file of f(gamma, C) in cd/klm (degrees) with symmetry `isym` and planes every
/// `dc` degrees, for one set of lamps of `flux` lm. Its lines: 1-25 the header, 26 the number
/// of lamp sets, 27-32 the set, 33-42 the direct ratios, 43 on the C angles, then the gamma
/// angles and the intensities.
std::string ldtFile(int isym, double dc, const std::vector<double>& gammas,
  const std::function<double(double, double)>& f, double flux = 1000)
{
  const int mc = static_cast<int>(std::lround(360 / dc));
  std::vector<double> cs;
  for (int i = 0; i < mc; ++i)
  {
    cs.push_back(i * dc);
  }
  std::vector<double> stored;
  switch (isym)
  {
    case 1:
      stored = { 0 };
      break;
    case 2:
      stored = degrees(0, 180, dc);
      break;
    case 3:
      stored = degrees(270, 450, dc);
      break;
    case 4:
      stored = degrees(0, 90, dc);
      break;
    default:
      stored = cs;
  }
  std::ostringstream s;
  s.precision(17);
  s << "TestPhotometry\n1\n"
    << isym << "\n"
    << mc << "\n"
    << dc << "\n"
    << gammas.size() << "\n"
    << (gammas[1] - gammas[0]) << "\n";
  s << "report\nluminaire\nnumber\nfile.ldt\n2026-12-01\n";
  s << "600\n0\n80\n500\n300\n0\n0\n0\n0\n";
  s << "100\n80\n1\n0\n1\n";
  s << "1\nLED\n" << flux << "\n3000\n1B\n40\n";
  for (int k = 0; k < 10; ++k)
  {
    s << "0.5\n";
  }
  s << join(cs, "\n") << "\n" << join(gammas, "\n") << "\n";
  for (double c : stored)
  {
    for (double g : gammas)
    {
      s << f(g, std::fmod(c, 360)) << "\n";
    }
  }
  return s.str();
}

/// The largest relative difference of two distributions' densities over many directions.
double densityDifference(const IntensityDistribution& a, const IntensityDistribution& b)
{
  RandomStream random(7, StreamPurpose::Gathering, 1);
  double worst = 0;
  for (int k = 0; k < 20000; ++k)
  {
    const Vec3 v = direction(std::acos(2 * random.uniform() - 1), 2 * Pi * random.uniform());
    const double fa = a.density(v), fb = b.density(v);
    worst = std::max(worst, std::abs(fa - fb) / std::max(1e-300, a.maximumDensity()));
  }
  return worst;
}

double cosPower(double gammaDegrees, double m)
{
  const double c = std::cos(gammaDegrees * Pi / 180);
  return c > 0 ? std::pow(c, m) : 0;
}
} // namespace

TEST(Photometry, FrameIsRightHandedWithCNinetyTowardsXCrossZ)
{
  const PhotometricFrame f = PhotometricFrame::fromNadir({ 0, 0, -2 }, { 3, 0, 0.5 });
  EXPECT_NEAR(length(f.z - Vec3(0, 0, -1)), 0, 1e-15);
  EXPECT_NEAR(length(f.x - Vec3(1, 0, 0)), 0, 1e-15);
  EXPECT_NEAR(length(f.y - cross(f.x, f.z)), 0, 1e-15);
  EXPECT_NEAR(length(f.y - Vec3(0, 1, 0)), 0, 1e-15);
  const Vec3 w(0.3, -0.4, 0.5);
  EXPECT_NEAR(length(f.toWorld(f.toLocal(w)) - w), 0, 1e-15);
  checks::expectError([] { PhotometricFrame::fromNadir({ 0, 0, 1 }, { 0, 0, -3 }); }, "parallel");
  checks::expectError([] { PhotometricFrame::fromNadir({ 0, 0, 0 }, { 1, 0, 0 }); }, "nadir");
}

TEST(Photometry, AnalyticDensitiesIntegrateToOne)
{
  EXPECT_NEAR(axialIntegral(IntensityDistribution::lambertian()), 1, 1e-6);
  EXPECT_NEAR(axialIntegral(IntensityDistribution::spot(0.4)), 1, 1e-4);
  EXPECT_NEAR(axialIntegral(IntensityDistribution::spot(0.4, 0.3)), 1, 1e-6);
  // A soft edge cut by the zenith, and the whole sphere.
  EXPECT_NEAR(axialIntegral(IntensityDistribution::spot(2.9, 0.5)), 1, 1e-6);
  EXPECT_NEAR(axialIntegral(IntensityDistribution::spot(Pi)), 1, 1e-6);
  EXPECT_NEAR(sphereIntegral(IntensityDistribution::spot(0.7, 0.2)), 1, 1e-3);
  EXPECT_TRUE(IntensityDistribution::lambertian().isLambertian());
  EXPECT_FALSE(IntensityDistribution::spot(0.4).isLambertian());
  EXPECT_DOUBLE_EQ(IntensityDistribution::lambertian().flux(), 1);
}

TEST(Photometry, SpotProfileAndMaximum)
{
  const IntensityDistribution s = IntensityDistribution::spot(0.5, 0.2);
  const double top = s.density(direction(0.1, 1));
  EXPECT_DOUBLE_EQ(top, s.maximumDensity());
  EXPECT_DOUBLE_EQ(s.density(direction(0.49, 2)), top);
  EXPECT_NEAR(s.density(direction(0.6, 3)), 0.5 * top, 1e-12);
  EXPECT_EQ(s.density(direction(0.71, 0)), 0);
  EXPECT_EQ(IntensityDistribution::lambertian().density({ 0, 0, -1 }), 0);
  EXPECT_DOUBLE_EQ(IntensityDistribution::lambertian().maximumDensity(), 1 / Pi);
  checks::expectError([] { IntensityDistribution::spot(0); }, "half angle");
  checks::expectError([] { IntensityDistribution::spot(4); }, "half angle");
  checks::expectError([] { IntensityDistribution::spot(0.5, -1); }, "soft edge");
}

TEST(Photometry, TableDensityIntegratesToOneAndFluxIsTheIntegral)
{
  // An asymmetric table on an uneven grid, wrapping from 300 degrees to 0, and a downlight.
  const IntensityDistribution t =
    table(radians({ 0, 10, 35, 60, 90, 120, 180 }), radians({ 0, 45, 90, 200, 300 }),
      [](double g, double c) { return 100 + 80 * std::cos(g) + 30 * std::sin(c) * std::sin(g); });
  EXPECT_NEAR(sphereIntegral(t), 1, 1e-4);
  const IntensityDistribution down =
    table(radians(degrees(0, 90, 5)), { 0.0 }, [](double g, double) { return std::cos(g); });
  EXPECT_NEAR(axialIntegral(down), 1, 1e-5);
  // flux() of a constant table is its candela times the solid angle of its gamma range.
  const IntensityDistribution flat =
    table(radians({ 20, 50, 80 }), radians({ 0, 180 }), [](double, double) { return 7; });
  EXPECT_NEAR(flat.flux(), 7 * 2 * Pi * (std::cos(20 * Pi / 180) - std::cos(80 * Pi / 180)), 1e-12);
  EXPECT_NEAR(flat.intensity(direction(0.6, 1)), 7, 1e-12);
  EXPECT_EQ(flat.density(direction(0.1, 1)), 0);
  EXPECT_NEAR(flat.maximumDensity(), 7 / flat.flux(), 1e-15);
}

TEST(Photometry, SamplesFollowTheDensity)
{
  expectSamplesFollowDensity(IntensityDistribution::lambertian(), -1, 1);
  // The hard edge on a bin boundary: the expected counts of a bin it crossed would be off by
  // the quadrature's resolution.
  expectSamplesFollowDensity(
    IntensityDistribution::spot(0.4), 1 - (1 - std::cos(0.4)) * 16 / 12, 2);
  expectSamplesFollowDensity(IntensityDistribution::spot(0.4, 0.5), std::cos(0.95), 3);
  expectSamplesFollowDensity(IntensityDistribution::spot(2.5, 1), -1, 4);
  const IntensityDistribution t =
    table(radians({ 0, 10, 35, 60, 90, 120, 180 }), radians({ 0, 45, 90, 200, 300 }),
      [](double g, double c) { return 100 + 80 * std::cos(g) + 60 * std::sin(c) * std::sin(g); });
  expectSamplesFollowDensity(t, -1, 5);
  // Steep cells, zeros inside the table and a single plane.
  const IntensityDistribution narrow = table(radians(degrees(0, 40, 4)), { 0.0 },
    [](double g, double) { return g < 0.3 ? std::pow(std::cos(g), 40) : 0; });
  expectSamplesFollowDensity(narrow, std::cos(0.75), 6);
  const IntensityDistribution lobe =
    table(radians(degrees(0, 90, 15)), radians(degrees(0, 345, 15)),
      [](double g, double c) { return std::abs(c - Pi / 2) < 0.3 ? std::sin(2 * g) : 0; });
  expectSamplesFollowDensity(lobe, 0, 7);
}

TEST(Photometry, SamplesNearCellCornersFollowTheDensity)
{
  // A table in 15 by 90 degree cells: one-degree bins on both sides of its cell corners
  // (gamma 60, C 180 and gamma 15, C 90), where an error in the cell CDF or the remainder of
  // the cell choice would show first.
  std::vector<double> gammas, planes;
  for (int g = 0; g <= 6; ++g)
  {
    gammas.push_back(g * 15 * Pi / 180);
  }
  for (int p = 0; p <= 4; ++p)
  {
    planes.push_back(p * 90 * Pi / 180);
  }
  const IntensityDistribution t = table(
    gammas, planes, [](double g, double c) { return (120 + 80 * std::cos(c)) * std::cos(g); });
  expectSamplesFollowDensity(t, 0, 8);
  const double degree = Pi / 180;
  const double corners[2][2] = { { 60, 180 }, { 15, 90 } };
  const int n = 2000000;
  std::vector<double> observed(32, 0), expected(32, 0);
  for (int k = 0; k < 2; ++k)
  {
    for (int a = 0; a < 4; ++a)
    {
      for (int b = 0; b < 4; ++b)
      {
        double sum = 0;
        for (int i = 0; i < 16; ++i)
        {
          for (int j = 0; j < 16; ++j)
          {
            const double g = (corners[k][0] - 2 + a + (i + 0.5) / 16) * degree;
            const double c = (corners[k][1] - 2 + b + (j + 0.5) / 16) * degree;
            sum += t.density(direction(g, c)) * std::sin(g);
          }
        }
        expected[k * 16 + a * 4 + b] = sum * degree * degree / 256 * n;
      }
    }
  }
  RandomStream random(75, StreamPurpose::Shooting, 75);
  for (int s = 0; s < n; ++s)
  {
    const double u1 = random.uniform(), u2 = random.uniform();
    const Vec3 v = t.sample(u1, u2);
    const double g = std::acos(v.z) / degree;
    double c = std::atan2(v.y, v.x) / degree;
    c += c < 0 ? 360 : 0;
    for (int k = 0; k < 2; ++k)
    {
      const int a = static_cast<int>(std::floor(g - corners[k][0] + 2));
      const int b = static_cast<int>(std::floor(c - corners[k][1] + 2));
      if (a >= 0 && a < 4 && b >= 0 && b < 4)
      {
        observed[k * 16 + a * 4 + b] += 1;
      }
    }
  }
  double chi = 0;
  for (int i = 0; i < 32; ++i)
  {
    ASSERT_GT(expected[i], 20);
    chi += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
  }
  EXPECT_LT(chi, 32 + 5 * std::sqrt(64.0)) << chi;
}

/**
 * The sampled density of a table is its evaluated intensity over its flux, to the resolution
 * of 4 million samples: bins are the table's own cells cut 3 by 3 (so that a wrong shape
 * inside a cell, a wrong cell weight or a wrong inverse CDF each show), and their expected
 * counts come from an 8-point Gauss-Legendre rule in gamma and C of intensity() sin(gamma),
 * exact for the bilinear intensity up to the sine's tenth derivative, not from the sampler's
 * closed forms. The chi-square statistic of a correct sampler has mean dof and deviation
 * sqrt(2 dof); the bound is five deviations above. The mean of the sampled intensity, the
 * flux-weighted quantity a kernel sees, must match its exact value within 5 standard errors.
 */
TEST(Photometry, SampledDensityEqualsEvaluatedIntensityCellByCell)
{
  const std::vector<double> gammas = radians({ 0, 15, 30, 45, 60, 75, 90 });
  const std::vector<double> planes = radians({ 0, 90, 180, 270, 360 });
  const IntensityDistribution t = table(
    gammas, planes, [](double g, double c) { return (120 + 80 * std::cos(c)) * std::cos(g); });
  const double nodes[8] = { -0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
    -0.1834346424956498, 0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
    0.9602898564975363 };
  const double weights[8] = { 0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
    0.3626837833783620, 0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
    0.1012285362903763 };
  const int cut = 3;
  const std::size_t nG = (gammas.size() - 1) * cut, nC = (planes.size() - 1) * cut;
  auto edge = [](const std::vector<double>& a, std::size_t i, int cut)
  {
    const std::size_t cell = i / cut;
    return a[cell] + (a[cell + 1] - a[cell]) * double(i % cut) / cut;
  };
  std::vector<double> probability(nG * nC, 0);
  double total = 0, meanIntensity = 0, meanSquare = 0;
  for (std::size_t a = 0; a < nG; ++a)
  {
    const double g0 = edge(gammas, a, cut),
                 g1 = a + 1 == nG ? gammas.back() : edge(gammas, a + 1, cut);
    for (std::size_t b = 0; b < nC; ++b)
    {
      const double c0 = edge(planes, b, cut),
                   c1 = b + 1 == nC ? planes.back() : edge(planes, b + 1, cut);
      double sum = 0, first = 0, second = 0;
      for (int i = 0; i < 8; ++i)
      {
        const double g = 0.5 * (g0 + g1) + 0.5 * (g1 - g0) * nodes[i];
        for (int j = 0; j < 8; ++j)
        {
          const double c = 0.5 * (c0 + c1) + 0.5 * (c1 - c0) * nodes[j];
          const double w = weights[i] * weights[j] * 0.25 * (g1 - g0) * (c1 - c0);
          const double value = t.intensity(direction(g, c));
          sum += w * value * std::sin(g);
          first += w * value * value * std::sin(g);
          second += w * value * value * value * std::sin(g);
        }
      }
      probability[a * nC + b] = sum;
      total += sum;
      meanIntensity += first;
      meanSquare += second;
    }
  }
  EXPECT_NEAR(total / t.flux(), 1, 1e-12);
  meanIntensity /= total;
  meanSquare /= total;
  const int n = 4000000;
  std::vector<double> observed(nG * nC, 0);
  RandomStream random(2026, StreamPurpose::Shooting, 22);
  double sampledIntensity = 0;
  for (int k = 0; k < n; ++k)
  {
    const double u1 = random.uniform(), u2 = random.uniform();
    const Vec3 v = t.sample(u1, u2);
    sampledIntensity += t.intensity(v);
    const double g = std::acos(std::clamp(v.z, -1.0, 1.0));
    double c = std::atan2(v.y, v.x);
    c += c < 0 ? 2 * Pi : 0;
    ASSERT_LE(g, gammas.back() + 1e-12);
    std::size_t a = std::upper_bound(gammas.begin(), gammas.end(), g) - gammas.begin() - 1;
    a = std::min(a, gammas.size() - 2);
    std::size_t b = std::upper_bound(planes.begin(), planes.end(), c) - planes.begin() - 1;
    b = std::min(b, planes.size() - 2);
    const double fg = (g - gammas[a]) / (gammas[a + 1] - gammas[a]);
    const double fc = (c - planes[b]) / (planes[b + 1] - planes[b]);
    const std::size_t sa = a * cut + std::min<std::size_t>(cut - 1, std::size_t(fg * cut));
    const std::size_t sb = b * cut + std::min<std::size_t>(cut - 1, std::size_t(fc * cut));
    observed[sa * nC + sb] += 1;
  }
  double chi = 0;
  int dof = -1;
  for (std::size_t i = 0; i < probability.size(); ++i)
  {
    const double expected = probability[i] / total * n;
    if (expected > 0)
    {
      chi += (observed[i] - expected) * (observed[i] - expected) / expected;
      ++dof;
    }
    else
    {
      EXPECT_EQ(observed[i], 0) << "a sample where the intensity is 0, bin " << i;
    }
  }
  EXPECT_LT(chi, dof + 5 * std::sqrt(2.0 * dof)) << "chi-square " << chi << ", dof " << dof;
  const double standardError = std::sqrt((meanSquare - meanIntensity * meanIntensity) / n);
  EXPECT_NEAR(sampledIntensity / n, meanIntensity, 5 * standardError);
  std::cout << "chi-square " << chi << " for " << dof << " dof; mean sampled intensity "
            << sampledIntensity / n << " vs " << meanIntensity << " +- " << standardError << "\n";
}

TEST(Photometry, TableIsRefusedWhenMalformed)
{
  checks::expectError([] { IntensityDistribution::tabulated({ 0 }, { 0 }, { 1 }); }, "two");
  checks::expectError(
    [] {
      IntensityDistribution::tabulated({ 0, 1 }, { 0 }, { 1 });
    },
    "needs 2 candela");
  checks::expectError(
    [] {
      IntensityDistribution::tabulated({ 1, 0 }, { 0 }, { 1, 1 });
    },
    "ascending");
  checks::expectError(
    [] {
      IntensityDistribution::tabulated({ 0, 1 }, { 0, 7 }, { 1, 1, 1, 1 });
    },
    "plane angle");
  checks::expectError([] { IntensityDistribution::tabulated({ 0, 1 }, { 0 }, { 1, -1 }); }, ">= 0");
  checks::expectError(
    [] {
      IntensityDistribution::tabulated({ 0, 1 }, { 0 }, { 1, NAN });
    },
    "finite");
  checks::expectError(
    [] {
      IntensityDistribution::tabulated({ 0, 1 }, { 0 }, { 0, 0 });
    },
    "no flux");
}

TEST(Photometry, IesCosinePowerGivesTheAnalyticFlux)
{
  TemporaryDirectory dir;
  const double m = 3, i0 = 800;
  const std::vector<double> vertical = degrees(0, 90, 1);
  const auto f = [&](double g, double) { return i0 * cosPower(g, m); };
  // A rotationally symmetric file, scaled by its multiplier and ballast factor.
  const Luminaire l =
    readPhotometricFile(dir.write("cos3.ies", iesFile(vertical, { 0 }, f, 2.5, 0.8)));
  const double exact = 2 * 2 * Pi * i0 / (m + 1);
  // The bilinear table's error against the smooth cosine is of order step^2 m^2 / 8.
  EXPECT_NEAR(l.lumens, exact, 2e-4 * exact);
  EXPECT_DOUBLE_EQ(l.lumens, l.distribution.flux());
  EXPECT_NEAR(l.distribution.intensity({ 0, 0, 1 }), 2 * i0, 1e-9);
  EXPECT_EQ(l.distribution.density({ 0, 0, -1 }), 0);
  EXPECT_NEAR(axialIntegral(l.distribution), 1, 1e-5);
  EXPECT_NEAR(l.width, 0.6, 1e-15);
  EXPECT_NEAR(l.length, 1.2, 1e-15);
  EXPECT_TRUE(l.warnings.empty());

  // The same in feet, a 1995 file, a CRLF file, and the full 0-180 vertical range.
  std::string feet = iesFile(degrees(0, 180, 1), { 0 }, f);
  feet.replace(feet.find(" 1 2 0.6"), 8, " 1 1 0.6");
  const Luminaire inFeet = parseIes(feet, "feet.ies");
  EXPECT_NEAR(inFeet.width, 0.6 * 0.3048, 1e-15);
  EXPECT_NEAR(inFeet.lumens, exact / 2, 2e-4 * exact);
  std::string crlf;
  for (char c : iesFile(vertical, { 0 }, f))
  {
    crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  }
  EXPECT_NEAR(parseIes(crlf, "crlf.ies").lumens, exact / 2, 2e-4 * exact);
  // DOS's end-of-file mark (^Z) right after the last value, as old files have it.
  std::string text = iesFile(vertical, { 0 }, f);
  text.erase(text.find_last_not_of("\n") + 1);
  const Luminaire dos = parseIes(text + "\x1a", "dos.ies");
  EXPECT_NEAR(dos.lumens, exact / 2, 2e-4 * exact);
  EXPECT_TRUE(dos.warnings.empty());

  // An uplight (90-180): 10 cd over the upper hemisphere, nothing below.
  const Luminaire up =
    parseIes(iesFile(degrees(90, 180, 10), { 0 }, [](double, double) { return 10.0; }), "up.ies");
  EXPECT_NEAR(up.lumens, 10 * 2 * Pi, 1e-12);
  EXPECT_EQ(up.distribution.density({ 0, 0, 1 }), 0);
  EXPECT_NEAR(up.distribution.density({ 0.3, 0, -1 }), 1 / (2 * Pi), 1e-12);

  // TILT=INCLUDE: the table is kept for the poses; the photometered flux is the candela's.
  const std::string tilt = "TILT=INCLUDE\n1\n3\n0 45 90\n0.5 0.7 0.9";
  const Luminaire tilted = parseIes(iesFile(vertical, { 0 }, f, 1, 1, tilt), "tilt.ies");
  EXPECT_NEAR(tilted.lumens, exact / 2, 2e-4 * exact);
  EXPECT_TRUE(tilted.warnings.empty());
  EXPECT_EQ(tilted.tilt.geometry, TiltTable::Geometry::Vertical);
  EXPECT_EQ(tilted.tilt.angles, (std::vector<double>{ 0, 45, 90 }));
  EXPECT_EQ(tilted.tilt.factors, (std::vector<double>{ 0.5, 0.7, 0.9 }));
  EXPECT_DOUBLE_EQ(tilted.tilt.factor(0), 0.5);
  EXPECT_DOUBLE_EQ(tilted.tilt.factor(22.5), 0.6);
  EXPECT_DOUBLE_EQ(tilted.tilt.factor(60), 0.7 + 0.2 * 15 / 45);
  EXPECT_DOUBLE_EQ(tilted.tilt.factor(120), 0.9); // clamped at the ends
  EXPECT_DOUBLE_EQ(tilted.tilt.factor(-5), 0.5);
  EXPECT_TRUE(l.tilt.empty());
  EXPECT_DOUBLE_EQ(l.tilt.factor(30), 1);
}

TEST(Photometry, IesBallastLampFactorScalesOnly1986And1991Files)
{
  // The ballast line "ballast factor, ballast-lamp photometric factor, watts": the second
  // field multiplies the candela in LM-63-1986/1991; 1995 and 2002 keep it for future use and
  // 2019 puts the file generation type there, which must change nothing (as in ies2rad).
  const auto f = [](double g, double) { return 100 * cosPower(g, 1); };
  const std::string base = iesFile(degrees(0, 90, 5), { 0 }, f);
  auto edition = [&](const std::string& header, const std::string& factor)
  {
    std::string text = base;
    text.replace(0, text.find('\n'), header);
    text.replace(text.find("\n1 1 40\n"), 8, "\n1 " + factor + " 40\n");
    return parseIes(text, "edition.ies");
  };
  const double flux = parseIes(base, "base.ies").lumens;
  EXPECT_NEAR(flux, 100 * Pi, 1e-3 * 100 * Pi);
  EXPECT_NEAR(edition("an old file without edition", "2").lumens, 2 * flux, 1e-12 * flux);
  EXPECT_NEAR(edition("IESNA91", "2").lumens, 2 * flux, 1e-12 * flux);
  for (const char* later : { "IESNA:LM-63-1995", "IESNA:LM-63-2002", "IES:LM-63-2019" })
  {
    EXPECT_NEAR(edition(later, "2").lumens, flux, 1e-12 * flux) << later;
    EXPECT_NEAR(edition(later, "0").lumens, flux, 1e-12 * flux) << later;
    EXPECT_NEAR(edition(later, "1.00001").lumens, flux, 1e-12 * flux) << later;
  }
  checks::expectError([&] { edition("IESNA91", "0"); },
    "edition.ies, line 5: the ballast-lamp photometric factor is 0");
  // Blank lines before the edition line are skipped: read as 1986, a 2019 file's generation
  // type 1.10100 scaled the flux by 10%.
  std::string blank = base;
  blank.replace(0, blank.find('\n'), "\n  \r\nIES:LM-63-2019");
  blank.replace(blank.find("\n1 1 40\n"), 8, "\n1 1.10100 40\n");
  EXPECT_NEAR(parseIes(blank, "blank.ies").lumens, flux, 1e-12 * flux);
  // A 1986 label may start with TILT: the TILT line is the word before its '='.
  std::string label = base;
  label.replace(0, label.find('\n'), "TILTABLE BRACKET, MODEL 7");
  EXPECT_NEAR(parseIes(label, "label.ies").lumens, flux, 1e-12 * flux);
}

TEST(Photometry, IesSymmetricFormsEqualTheFullTable)
{
  const std::vector<double> vertical = degrees(0, 180, 5);
  const auto full = degrees(0, 360, 15);
  struct Case
  {
    std::vector<double> planes;
    std::function<double(double)> inC;
  };
  const Case cases[] = {
    { { 0 }, [](double) { return 1.0; } },
    { degrees(0, 90, 15), [](double c) { return 1 + 0.5 * std::cos(2 * c * Pi / 180); } },
    { degrees(0, 180, 15), [](double c) { return 1 + 0.5 * std::cos(c * Pi / 180); } },
    { degrees(90, 270, 15), [](double c) { return 1 + 0.5 * std::sin(c * Pi / 180); } },
  };
  for (const Case& k : cases)
  {
    const auto f = [&](double g, double c)
    { return 100 * (1.2 + std::cos(g * Pi / 180)) * k.inC(c); };
    const Luminaire a = parseIes(iesFile(vertical, k.planes, f), "symmetric.ies");
    const Luminaire b = parseIes(iesFile(vertical, full, f), "full.ies");
    EXPECT_LT(densityDifference(a.distribution, b.distribution), 1e-12) << k.planes.back();
    EXPECT_NEAR(a.lumens, b.lumens, 1e-9 * b.lumens);
  }
}

TEST(Photometry, IesCNinetyLiesTowardsPlusY)
{
  // Light only in the C = 90 plane, 30 to 60 degrees from the nadir.
  const auto f = [](double g, double c) { return c == 90 && g >= 30 && g <= 60 ? 500.0 : 0.0; };
  const Luminaire l = parseIes(iesFile(degrees(0, 90, 15), degrees(0, 360, 90), f), "c90.ies");
  const PhotometricFrame frame = PhotometricFrame::fromNadir({ 0, 0, -1 }, { 1, 0, 0 });
  const Vec3 towardsY = frame.toLocal(normalize(Vec3(0, 1, -1)));
  EXPECT_NEAR(l.distribution.density(towardsY), l.distribution.maximumDensity(), 1e-12);
  EXPECT_EQ(l.distribution.density(frame.toLocal(normalize(Vec3(0, -1, -1)))), 0);
  EXPECT_LT(l.distribution.density(frame.toLocal(normalize(Vec3(1, 0, -1)))),
    0.1 * l.distribution.maximumDensity());
  // The mean sampled direction, in the world, leans towards +y = x cross z.
  Vec3 mean;
  RandomStream random(3, StreamPurpose::Shooting, 9);
  for (int k = 0; k < 10000; ++k)
  {
    const double u1 = random.uniform(), u2 = random.uniform();
    mean += frame.toWorld(l.distribution.sample(u1, u2)) / 10000;
  }
  EXPECT_GT(mean.y, 0.3);
  EXPECT_NEAR(mean.x, 0, 0.05);
  EXPECT_LT(mean.z, -0.4);
}

TEST(Photometry, EulumdatSymmetriesAndFlux)
{
  TemporaryDirectory dir;
  const std::vector<double> gammas = degrees(0, 180, 1);
  const double m = 2;
  const auto cosine = [&](double g, double) { return 300 * cosPower(g, m); };
  // cd/klm for 2000 lm: twice the values in candela.
  const Luminaire axial =
    readPhotometricFile(dir.write("axial.LDT", ldtFile(1, 15, gammas, cosine, 2000)));
  const double exact = 2 * 300 * 2 * Pi / (m + 1);
  EXPECT_NEAR(axial.lumens, exact, 1e-3 * exact);
  EXPECT_NEAR(axial.length, 0.5, 1e-15);
  EXPECT_NEAR(axial.width, 0.3, 1e-15);

  const std::function<double(double)> inC[] = {
    [](double) { return 1.0; },
    [](double c) { return 1 + 0.5 * std::cos(c * Pi / 180); },
    [](double c) { return 1 + 0.5 * std::sin(c * Pi / 180); },
    [](double c) { return 1 + 0.5 * std::cos(2 * c * Pi / 180); },
  };
  for (int isym = 1; isym <= 4; ++isym)
  {
    const auto f = [&](double g, double c)
    { return 100 * (1.2 + std::cos(g * Pi / 180)) * inC[isym - 1](c); };
    const Luminaire a = parseEulumdat(ldtFile(isym, 15, gammas, f), "symmetric.ldt");
    const Luminaire b = parseEulumdat(ldtFile(0, 15, gammas, f), "full.ldt");
    EXPECT_LT(densityDifference(a.distribution, b.distribution), 1e-12) << "Isym " << isym;
    EXPECT_NEAR(a.lumens, b.lumens, 1e-9 * b.lumens);
  }
  // The same distribution from both formats.
  const auto f = [](double g, double c)
  { return 100 * (1.2 + std::cos(g * Pi / 180)) * (1 + 0.5 * std::sin(c * Pi / 180)); };
  const Luminaire ldt = parseEulumdat(ldtFile(3, 15, gammas, f), "same.ldt");
  const Luminaire ies = parseIes(iesFile(gammas, degrees(0, 360, 15), f), "same.ies");
  EXPECT_LT(densityDifference(ldt.distribution, ies.distribution), 1e-12);
  EXPECT_NEAR(ldt.lumens, ies.lumens, 1e-9 * ies.lumens);

  // C = 90 towards +y, as in IES.
  const auto c90 = [](double g, double c) { return c == 90 && g >= 30 && g <= 60 ? 500.0 : 0.0; };
  const Luminaire towards = parseEulumdat(ldtFile(0, 90, gammas, c90), "c90.ldt");
  EXPECT_NEAR(towards.distribution.density(normalize(Vec3(0, 1, 1))),
    towards.distribution.maximumDensity(), 1e-12);
  EXPECT_EQ(towards.distribution.density(normalize(Vec3(0, -1, 1))), 0);
}

TEST(Photometry, BadIesFilesNameTheLineAndField)
{
  const auto f = [](double g, double) { return 100 * cosPower(g, 1); };
  const std::string good = iesFile({ 0, 45, 90 }, { 0 }, f);
  ASSERT_NO_THROW(parseIes(good, "good.ies"));
  auto with = [&](const std::string& from, const std::string& to)
  {
    std::string text = good;
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  };
  auto error = [](const std::string& text)
  { return checks::errorOf([&] { parseIes(text, "bad.ies"); }); };
  std::string e = error(good.substr(0, good.rfind(' ')));
  EXPECT_NE(e.find("bad.ies: the file ends"), std::string::npos) << e;
  EXPECT_NE(e.find("truncated"), std::string::npos) << e;
  // The lumens per lamp are not used (the flux is the table's integral): 0 is named, not
  // refused.
  const Luminaire zero = parseIes(with("1 -1 1 3 1", "1 0 1 3 1"), "zero.ies");
  ASSERT_EQ(zero.warnings.size(), 1u);
  EXPECT_NE(zero.warnings[0].find("zero.ies, line 4: the lumens per lamp are 0, neither"),
    std::string::npos)
    << zero.warnings[0];
  EXPECT_EQ(zero.lumens, parseIes(good, "good.ies").lumens);
  e = error(with("1 -1 1 3", "1 -1 x 3"));
  EXPECT_NE(e.find("bad.ies, line 4: the candela multiplier is 'x'"), std::string::npos) << e;
  e = error(with("0 45 90", "0 95 90"));
  EXPECT_NE(e.find("line 6: vertical angle 3 of 3 is 90 degrees, not above"), std::string::npos)
    << e;
  e = error(with("0 45 90", "0 45 190"));
  EXPECT_NE(e.find("line 6: vertical angle 3 of 3 is 190"), std::string::npos) << e;
  e = error(with("\n100 ", "\n-100 "));
  EXPECT_NE(
    e.find("line 8: the candela value at horizontal angle 0, vertical angle 0"), std::string::npos)
    << e;
  EXPECT_NE(e.find("must be >= 0"), std::string::npos) << e;
  e = error(with("\n100 ", "\nnan "));
  EXPECT_NE(e.find("line 8"), std::string::npos) << e;
  EXPECT_NE(e.find("not a finite number"), std::string::npos) << e;
  e = error(with("\n100 ", "\ninf "));
  EXPECT_NE(e.find("'inf', not a finite number"), std::string::npos) << e;
  e = error(with("1 -1 1 3 1", "1 -1 1 3 900000000"));
  EXPECT_NE(e.find("line 4: the number of horizontal angles is 9e+08"), std::string::npos) << e;
  e = error(with("1 -1 1 3 1", "1 -1 1 9000 9000"));
  EXPECT_NE(e.find("line 4: 9000 vertical by 9000"), std::string::npos) << e;
  e = error(with("1 -1 1 3 1", "1 -1 1 3000 3"));
  EXPECT_NE(e.find("more than the rest of the file holds"), std::string::npos) << e;
  e = error(with("1 -1 1 3 1", "1 -1 1 2.5 1"));
  EXPECT_NE(e.find("the number of vertical angles is 2.5"), std::string::npos) << e;
  e = error(with("TILT=NONE", "TILT=lamp.tlt"));
  EXPECT_NE(e.find("line 3: TILT=lamp.tlt refers to a separate tilt file"), std::string::npos) << e;
  e = error(with("TILT=NONE", "[MORE] no tilt"));
  EXPECT_NE(e.find("no TILT= line"), std::string::npos) << e;
  e = error(with(" 1 2 0.6", " 4 2 0.6"));
  EXPECT_NE(e.find("line 4: the photometric type is 4"), std::string::npos) << e;
  e = error(with(" 1 2 0.6", " 1 3 0.6"));
  EXPECT_NE(e.find("the units type"), std::string::npos) << e;
  e = error(with("\n1 1 40", "\n0 1 40"));
  EXPECT_NE(e.find("line 5: the ballast factor is 0"), std::string::npos) << e;
  e = error(iesFile({ 0, 45, 90 }, { 0 }, [](double, double) { return 0.0; }));
  EXPECT_NE(e.find("every candela value is 0"), std::string::npos) << e;
  e = error(with("TILT=NONE", "TILT=INCLUDE\n1\n2\n0 90\n1 -1"));
  EXPECT_NE(e.find("line 7: tilt multiplying factor 2 of 2 is -1"), std::string::npos) << e;
  // Malformed TILT=INCLUDE blocks, each named by its line.
  e = error(with("TILT=NONE", "TILT=INCLUDE\n4\n2\n0 90\n1 1"));
  EXPECT_NE(e.find("line 4: the lamp-to-luminaire geometry"), std::string::npos) << e;
  EXPECT_NE(e.find("is 4: it must be a whole number from 1 to 3"), std::string::npos) << e;
  e = error(with("TILT=NONE", "TILT=INCLUDE\n1\n0\n\n"));
  EXPECT_NE(e.find("line 5: the number of tilt angles is 0"), std::string::npos) << e;
  e = error(with("TILT=NONE", "TILT=INCLUDE\n1\n3\n0 45 30\n1 1 1"));
  EXPECT_NE(
    e.find("line 6: tilt angle 3 of 3 is 30 degrees, not above the previous 45"), std::string::npos)
    << e;
  // A count too large reads the factors as angles: the message offers the count they end at.
  e = error(with("TILT=NONE", "TILT=INCLUDE\n1\n5\n0 90\n1 0.5"));
  EXPECT_NE(
    e.find("line 7: tilt angle 3 of 5 is 1 degrees, not above the previous 90"), std::string::npos)
    << e;
  EXPECT_NE(e.find("(if they end at 90, the number of tilt angles is 2, not 5)"), std::string::npos)
    << e;
  e = error(with("1 -1 1 3 1", "1 -1 1 4 1"));
  EXPECT_NE(e.find("the number of vertical angles is 3, not 4"), std::string::npos) << e;
  e = error(with("TILT=NONE", "TILT=INCLUDE\n1\n2\n0 400\n1 1"));
  EXPECT_NE(e.find("line 6: tilt angle 2 of 2 is 400 degrees"), std::string::npos) << e;
  e = error(with("TILT=NONE", "TILT=INCLUDE\n2\n2\n0 90\n1 x"));
  EXPECT_NE(
    e.find("line 7: tilt multiplying factor 2 of 2 is 'x', not a finite number"), std::string::npos)
    << e;
  e = error("IESNA:LM-63-2002\nTILT=INCLUDE\n1\n3\n0 45 90\n1 0.9");
  EXPECT_NE(e.find("bad.ies: the file ends (after line 6) before tilt multiplying factor 3 of 3"),
    std::string::npos)
    << e;
  // The flux is bounded by MaximumLightPower, 1e30 lm, which keeps the single-precision outputs
  // finite: a uniform sphere of 1e28 cd emits 4 pi 1e28 lm and is read, one of 1e29 cd is not.
  auto sphere = [](double cd) {
    return iesFile({ 0, 90, 180 }, { 0 }, [=](double, double) { return cd; });
  };
  EXPECT_NEAR(parseIes(sphere(1e28), "sphere.ies").lumens, 4 * Pi * 1e28, 1e-12 * 4 * Pi * 1e28);
  e = error(sphere(1e29));
  EXPECT_NE(e.find("bad.ies: the intensity table emits 1.25664e+30 lm, more than 1e+30 lm"),
    std::string::npos)
    << e;
  // Horizontal angles that are no LM-63 symmetry.
  const std::string odd = iesFile({ 0, 45, 90 }, { 0, 45, 120 }, f);
  e = error(odd);
  EXPECT_NE(e.find("line 7: the horizontal angles run from 0 to 120"), std::string::npos) << e;
  // A full turn may leave out 360, one step of its own, and no more: 0 to 200 would make up
  // the intensities over 160 degrees.
  EXPECT_NO_THROW(parseIes(iesFile({ 0, 45, 90 }, degrees(0, 350, 10), f), "turn.ies"));
  e = error(iesFile({ 0, 45, 90 }, degrees(0, 200, 10), f));
  EXPECT_NE(e.find("line 7: the horizontal angles run from 0 to 200"), std::string::npos) << e;
  // Angles listed from the highest: no advice about their count.
  e = error(with("0 45 90", "90 45 0"));
  EXPECT_NE(e.find("line 6: vertical angle 2 of 3 is 45 degrees, not above the first, 90: the "
                   "angles must ascend strictly, from the lowest"),
    std::string::npos)
    << e;
  EXPECT_NE(error("").find("is empty"), std::string::npos);
}

TEST(Photometry, EulumdatLampSetsAreAlternativesScaledToTheFirst)
{
  // Two standard sets of lamps (1 x 1000 lm and 2 x 1500 lm) are alternative equipments: the
  // cd/klm intensities scale to the first set's flux, not to the 4000 lm of both. Each set's
  // six fields come together (number, type, flux, colour, rendering group, watts), as in the
  // files of luminaire makers.
  const std::vector<double> gammas = degrees(0, 90, 15);
  auto f = [](double g, double) { return 300 * std::cos(g * Pi / 180); };
  const std::string one = ldtFile(1, 90, gammas, f, 1000);
  const std::string block = "\n1\n1\nLED\n1000\n3000\n1B\n40\n";
  const std::size_t at = one.find(block);
  ASSERT_NE(at, std::string::npos);
  std::string two = one;
  two.replace(at, block.size(),
    "\n2\n1\nLED Module\n1000\n3000\n1B\n40\n2\nLED Module\n3000\nnw\n1A/>90\n80\n");
  const Luminaire single = parseEulumdat(one, "one.ldt");
  const Luminaire sets = parseEulumdat(two, "two.ldt");
  EXPECT_NEAR(sets.lumens, single.lumens, 1e-12 * single.lumens);
  // 300 cos(gamma) cd/klm at 1000 lm over the lower hemisphere: 300 pi lm.
  EXPECT_NEAR(single.lumens, 300 * Pi, 0.01 * 300 * Pi);
  ASSERT_EQ(sets.warnings.size(), 1u);
  EXPECT_NE(
    sets.warnings[0].find("2 sets of lamps, read as alternative equipments"), std::string::npos)
    << sets.warnings[0];
  EXPECT_TRUE(single.warnings.empty());
}

/// An IES LM-63-2002 type B file of the candela f(H, V) at the given angles (degrees).
std::string typeBFile(const std::vector<double>& vertical, const std::vector<double>& horizontal,
  const std::function<double(double, double)>& f, double multiplier = 1)
{
  std::ostringstream s;
  s.precision(17);
  s << "IESNA:LM-63-2002\n[TEST] type B\nTILT=NONE\n1 -1 " << multiplier << " " << vertical.size()
    << " " << horizontal.size() << " 2 2 0 0 0\n1 1 100\n";
  s << join(vertical, " ") << "\n" << join(horizontal, " ") << "\n";
  for (double h : horizontal)
  {
    for (double v : vertical)
    {
      s << f(h, v) << " ";
    }
    s << "\n";
  }
  return s.str();
}

/// The light-frame direction of type B angles (degrees): the half-plane H about the
/// photometric horizontal +x, from the nadir towards -y, and V within it towards +x.
Vec3 typeBDirection(double h, double v)
{
  const double hr = h * Pi / 180, vr = v * Pi / 180;
  return Vec3(std::sin(vr), -std::cos(vr) * std::sin(hr), std::cos(vr) * std::cos(hr));
}

/// Radiance's type B angles (degrees) of a light-frame emission direction, as lib/source.cal
/// computes them from the ray direction D into the source (D = -emission, in a world where the
/// light's nadir is -z): srcB_horiz = atan2(Dy, Dz), srcB_vert = atan2(-Dx, Dz).
void radianceTypeB(const Vec3& emission, double& h, double& v)
{
  const Vec3 d(-emission.x, -emission.y, emission.z);
  h = std::atan2(d.y, d.z) * 180 / Pi;
  v = std::atan2(-d.x, d.z) * 180 / Pi;
}

TEST(Photometry, IesTypeBTurnsAboutThePhotometricHorizontal)
{
  // An asymmetric floodlight: every table point must come back, times the multiplier, in the
  // direction the analytic conversion gives it, and its density integrates to 1.
  const std::vector<double> vertical = degrees(-90, 90, 15), horizontal = degrees(-90, 90, 30);
  auto f = [](double h, double v)
  {
    const double hr = h * Pi / 180, vr = v * Pi / 180;
    return (100 + 50 * std::sin(hr) + 20 * std::sin(vr)) * std::cos(hr) * std::cos(vr) + 1;
  };
  const Luminaire b = parseIes(typeBFile(vertical, horizontal, f, 2), "b.ies");
  for (double h : horizontal)
  {
    for (double v : vertical)
    {
      if (std::abs(v) == 90)
      {
        continue; // the poles of the photometric horizontal are one direction for every H
      }
      EXPECT_NEAR(b.distribution.intensity(typeBDirection(h, v)), 2 * f(h, v), 1e-9 * f(h, v))
        << "H " << h << ", V " << v;
      // The same angles as Radiance's: H everywhere, V in the plane H = 0 (elsewhere
      // source.cal's V is a projection, atan(tan V / cos H)).
      double rh, rv;
      radianceTypeB(typeBDirection(h, v), rh, rv);
      EXPECT_NEAR(rh, h, 1e-9) << "H " << h << ", V " << v;
      if (std::abs(h) < 90)
      {
        EXPECT_NEAR(std::tan(rv * Pi / 180) * std::cos(h * Pi / 180), std::tan(v * Pi / 180), 1e-9)
          << "H " << h << ", V " << v;
      }
    }
  }
  EXPECT_NEAR(sphereIntegral(b.distribution), 1, 2e-3);
  EXPECT_NEAR(b.lumens, b.distribution.flux(), 1e-12 * b.lumens);

  // A narrow lobe at (H, V) = (30, 0) lights -y and one at (0, 30) lights +x, below a point
  // light 2 m up, as Radiance's ies2rad model of the same file does; the old reading turned
  // both by 90 degrees about the nadir (to +x and +y).
  auto lobe = [&](double h0, double v0)
  {
    return parseIes(
      typeBFile(degrees(-90, 90, 10), degrees(-90, 90, 10),
        [&](double h, double v)
        { return 10 + 1000 * std::exp(-((h - h0) * (h - h0) + (v - v0) * (v - v0)) / 50); }),
      "lobe.ies");
  };
  const double t = std::tan(30 * Pi / 180);
  const Vec3 plusX = normalize(Vec3(t, 0, 1)), minusY = normalize(Vec3(0, -t, 1));
  const Luminaire lobeH = lobe(30, 0), lobeV = lobe(0, 30);
  EXPECT_NEAR(lobeH.distribution.intensity(minusY), 1010, 1e-9);
  EXPECT_NEAR(lobeV.distribution.intensity(plusX), 1010, 1e-9);
  for (const Vec3& elsewhere : { normalize(Vec3(-t, 0, 1)), normalize(Vec3(0, t, 1)) })
  {
    EXPECT_NEAR(lobeH.distribution.intensity(elsewhere), 10, 1e-6);
    EXPECT_NEAR(lobeV.distribution.intensity(elsewhere), 10, 1e-6);
  }
  EXPECT_NEAR(lobeH.distribution.intensity(plusX), 10, 1e-6);
  EXPECT_NEAR(lobeV.distribution.intensity(minusY), 10, 1e-6);
  // Behind the luminaire (|H| > 90) the file says nothing: no light there.
  EXPECT_EQ(b.distribution.intensity(typeBDirection(120, 10)), 0);
  EXPECT_EQ(b.distribution.intensity(Vec3(0, 0, -1)), 0);
  expectSamplesFollowDensity(b.distribution, -1, 31);

  // Lateral symmetry (H from 0 to 90) equals its mirrored full table.
  auto g = [](double h, double v)
  { return (100 + 40 * std::cos(2 * h * Pi / 180)) * (95 - v) / 95; };
  const Luminaire half = parseIes(typeBFile(vertical, degrees(0, 90, 30), g), "half.ies");
  const Luminaire full = parseIes(typeBFile(vertical, horizontal, g), "full.ies");
  EXPECT_LT(densityDifference(half.distribution, full.distribution), 1e-12);
  EXPECT_NEAR(half.lumens, full.lumens, 1e-12 * full.lumens);

  // One horizontal angle: symmetric about the beam, I(gamma) = I(V = gamma).
  const Luminaire axial = parseIes(typeBFile(degrees(0, 90, 15), { 0 },
                                     [](double, double v) { return 200 * std::cos(v * Pi / 180); }),
    "axial.ies");
  EXPECT_NEAR(axial.distribution.intensity(direction(0.5, 2.0)), 200 * std::cos(0.5), 2);
  EXPECT_NEAR(axial.lumens, 200 * Pi, 0.01 * 200 * Pi);

  // The back half (H 90 to 270) as given: light only behind.
  const Luminaire back = parseIes(typeBFile(vertical, degrees(90, 270, 30), g), "back.ies");
  EXPECT_EQ(back.distribution.intensity(typeBDirection(0, 0)), 0);
  EXPECT_NEAR(back.distribution.intensity(typeBDirection(180, 0)), g(180, 0), 1e-9 * g(180, 0));
  EXPECT_NEAR(sphereIntegral(back.distribution), 1, 2e-3);
}

/// An IES LM-63-2002 type A file of the candela f(H, V) at the given angles (degrees).
std::string typeAFile(const std::vector<double>& vertical, const std::vector<double>& horizontal,
  const std::function<double(double, double)>& f)
{
  std::string text = typeBFile(vertical, horizontal, f);
  text.replace(text.find(" 2 2 0 0 0"), 10, " 3 2 0 0 0");
  return text;
}

/// The light-frame direction of type A angles (degrees): planes through the vertical axis, H
/// clockwise seen from above from C = 0 (+x), V the elevation (-90 the nadir, +z of the frame).
Vec3 typeADirection(double h, double v)
{
  const double hr = h * Pi / 180, vr = v * Pi / 180;
  return Vec3(std::cos(vr) * std::cos(hr), -std::cos(vr) * std::sin(hr), -std::sin(vr));
}

TEST(Photometry, IesTypeAHasVerticalPlanesCountedClockwise)
{
  // An asymmetric headlamp-like beam about the photometric horizontal: every table point comes
  // back in the direction LM-63-2002's definitions give it, and the density integrates to 1.
  const std::vector<double> vertical = degrees(-90, 90, 15), horizontal = degrees(-90, 90, 30);
  auto f = [](double h, double v)
  {
    const double hr = h * Pi / 180, vr = v * Pi / 180;
    return (100 + 60 * std::sin(hr) + 30 * std::sin(vr)) * std::cos(hr) * std::cos(vr) + 2;
  };
  const Luminaire a = parseIes(typeAFile(vertical, horizontal, f), "a.ies");
  EXPECT_TRUE(a.warnings.empty());
  for (double h : horizontal)
  {
    for (double v : vertical)
    {
      if (std::abs(v) == 90)
      {
        continue; // the poles are one direction for every H
      }
      EXPECT_NEAR(a.distribution.intensity(typeADirection(h, v)), f(h, v), 1e-9 * f(h, v))
        << "H " << h << ", V " << v;
    }
  }
  EXPECT_NEAR(sphereIntegral(a.distribution), 1, 2e-3);
  // Between the table's angles the interpolation is bilinear in H and V.
  EXPECT_NEAR(a.distribution.intensity(typeADirection(15, 7.5)),
    0.25 * (f(0, 0) + f(30, 0) + f(0, 15) + f(30, 15)), 1e-9 * f(15, 7.5));
  // Positive H turns clockwise seen from above (towards -y), V = -90 is the nadir.
  EXPECT_GT(a.distribution.intensity(normalize(Vec3(1, -0.5, 0))),
    a.distribution.intensity(normalize(Vec3(1, 0.5, 0))));
  EXPECT_NEAR(a.distribution.intensity(Vec3(0, 0, 1)), f(0, -90), 1e-9);
  // Behind the lamp (|H| > 90) the file says nothing: no light there.
  EXPECT_EQ(a.distribution.intensity(typeADirection(150, 10)), 0);
  expectSamplesFollowDensity(a.distribution, -1, 37);

  // Lateral symmetry (H from 0 to 90) equals its mirrored full table.
  auto g = [](double h, double v)
  { return (100 + 40 * std::cos(2 * h * Pi / 180)) * (95 - v) / 95; };
  const Luminaire half = parseIes(typeAFile(vertical, degrees(0, 90, 30), g), "half.ies");
  const Luminaire full = parseIes(typeAFile(vertical, horizontal, g), "full.ies");
  EXPECT_LT(densityDifference(half.distribution, full.distribution), 1e-12);
  EXPECT_NEAR(half.lumens, full.lumens, 1e-12 * full.lumens);

  // One horizontal angle: the same in every vertical plane. 100 cd from V = -90 to 90 is the
  // uniform sphere, 400 pi lm.
  const Luminaire round =
    parseIes(typeAFile(vertical, { 0 }, [](double, double) { return 100.0; }), "round.ies");
  EXPECT_NEAR(round.lumens, 400 * Pi, 1e-9 * 400 * Pi);
  // A whole turn of H (-180 to 180) is the whole sphere, and equals type C with gamma = 90 + V
  // and C = -H.
  auto c = [](double gamma, double cc)
  {
    return 50 +
      30 * std::cos(gamma * Pi / 180) *
      (1 + 0.5 * std::cos(cc * Pi / 180) + 0.3 * std::sin(cc * Pi / 180));
  };
  const Luminaire turn = parseIes(
    typeAFile(vertical, degrees(-180, 180, 30), [&](double h, double v) { return c(90 + v, -h); }),
    "turn.ies");
  const Luminaire typeC = parseIes(iesFile(degrees(0, 180, 15), degrees(0, 360, 30), c), "c.ies");
  EXPECT_LT(densityDifference(turn.distribution, typeC.distribution), 1e-9);
  // The same turn from 0 to 360 is taken as given, not mirrored.
  const Luminaire fromZero = parseIes(
    typeAFile(vertical, degrees(0, 360, 30), [&](double h, double v) { return c(90 + v, -h); }),
    "zero.ies");
  EXPECT_LT(densityDifference(fromZero.distribution, typeC.distribution), 1e-9);
}

TEST(Photometry, IesLuminousOpeningShapes)
{
  // The signed width, length and height of each edition's shapes, in metres (units 2).
  struct Case
  {
    const char* edition;
    double w, l, h;
    OpeningShape shape;
    const char* name;
    double alongX, alongY;
    bool warns;
  };
  const Case cases[] = {
    { "IESNA:LM-63-2002", 0, 0, 0, OpeningShape::None, "point", 0, 0, false },
    { "IESNA:LM-63-2002", 0.3, 1.2, 0, OpeningShape::Rectangle, "rectangle", 1.2, 0.3, false },
    { "IESNA:LM-63-2002", 0.3, 1.2, 0.1, OpeningShape::Rectangle, "rectangle with luminous sides",
      1.2, 0.3, true },
    { "IESNA:LM-63-2002", -0.2, -0.2, 0, OpeningShape::Ellipse, "circle", 0.2, 0.2, false },
    { "IESNA:LM-63-1995", -0.2, 0, 0, OpeningShape::Ellipse, "circle", 0.2, 0.2, false },
    { "IESNA:LM-63-2002", -0.2, -0.4, 0, OpeningShape::Ellipse, "ellipse", 0.4, 0.2, false },
    { "IESNA:LM-63-2002", -0.2, -0.2, 0.3, OpeningShape::Ellipse, "vertical cylinder", 0.2, 0.2,
      true },
    { "IESNA:LM-63-2002", -0.2, -0.2, -0.2, OpeningShape::Ellipse, "sphere", 0.2, 0.2, true },
    { "IESNA:LM-63-1995", -0.2, 0, -0.2, OpeningShape::Ellipse, "sphere", 0.2, 0.2, true },
    { "IESNA:LM-63-2002", -0.1, 0.8, -0.1, OpeningShape::Rectangle,
      "horizontal cylinder along the photometric horizontal", 0.8, 0.1, true },
    { "IESNA:LM-63-2002", 0.8, -0.1, -0.1, OpeningShape::Rectangle,
      "horizontal cylinder across the photometric horizontal", 0.1, 0.8, true },
    { "IESNA:LM-63-2002", 0, -0.2, -0.2, OpeningShape::None,
      "vertical disc facing the photometric horizontal", 0, 0, true },
    { "IESNA:LM-63-2002", 0.2, -0.2, 0, OpeningShape::None, "unknown shape", 0, 0, true },
  };
  const auto f = [](double g, double) { return 100 * cosPower(g, 1); };
  for (const Case& c : cases)
  {
    std::string text = iesFile({ 0, 45, 90 }, { 0 }, f);
    text.replace(0, text.find('\n'), c.edition);
    std::ostringstream sizes;
    sizes << " 1 2 " << c.w << " " << c.l << " " << c.h << "\n";
    text.replace(text.find(" 1 2 0.6 1.2 0\n"), 15, sizes.str());
    const Luminaire l = parseIes(text, "shape.ies");
    EXPECT_EQ(l.opening, c.shape) << c.name;
    EXPECT_EQ(l.openingName, c.name);
    if (c.shape != OpeningShape::None)
    {
      EXPECT_NEAR(l.length, c.alongX, 1e-15) << c.name;
      EXPECT_NEAR(l.width, c.alongY, 1e-15) << c.name;
    }
    // Apart, for the light that emits from the opening alone.
    EXPECT_EQ(!l.openingWarnings.empty(), c.warns) << c.name;
    EXPECT_TRUE(l.warnings.empty()) << c.name;
  }
  // Feet: a 2 by 4 foot troffer.
  std::string feet = iesFile({ 0, 45, 90 }, { 0 }, f);
  feet.replace(feet.find(" 1 2 0.6 1.2 0\n"), 15, " 1 1 2 4 0\n");
  const Luminaire troffer = parseIes(feet, "troffer.ies");
  EXPECT_EQ(troffer.opening, OpeningShape::Rectangle);
  EXPECT_NEAR(troffer.length, 4 * 0.3048, 1e-15);
  EXPECT_NEAR(troffer.width, 2 * 0.3048, 1e-15);

  // EULUMDAT: the luminous area (mm), round when its width is 0.
  const std::vector<double> gammas = degrees(0, 90, 30);
  const std::string ldt = ldtFile(1, 90, gammas, f);
  const Luminaire rectangle = parseEulumdat(ldt, "r.ldt");
  EXPECT_EQ(rectangle.opening, OpeningShape::Rectangle);
  EXPECT_NEAR(rectangle.length, 0.5, 1e-15);
  EXPECT_NEAR(rectangle.width, 0.3, 1e-15);
  std::string disc = ldt;
  const std::string area = "\n500\n300\n0\n";
  disc.replace(disc.find(area), area.size(), "\n250\n0\n0\n");
  const Luminaire circle = parseEulumdat(disc, "c.ldt");
  EXPECT_EQ(circle.opening, OpeningShape::Ellipse);
  EXPECT_EQ(circle.openingName, "circle");
  EXPECT_NEAR(circle.length, 0.25, 1e-15);
  EXPECT_NEAR(circle.width, 0.25, 1e-15);
  EXPECT_TRUE(circle.warnings.empty());
  EXPECT_TRUE(circle.openingWarnings.empty());
  // No luminous area: the luminaire's own outline (600 mm round), with a warning.
  std::string body = ldt;
  const std::string sizes = "\n600\n0\n80\n500\n300\n";
  body.replace(body.find(sizes), sizes.size(), "\n600\n0\n80\n0\n0\n");
  const Luminaire outline = parseEulumdat(body, "b.ldt");
  EXPECT_EQ(outline.opening, OpeningShape::Ellipse);
  EXPECT_NEAR(outline.length, 0.6, 1e-15);
  EXPECT_TRUE(outline.warnings.empty());
  ASSERT_EQ(outline.openingWarnings.size(), 1u);
  EXPECT_NE(outline.openingWarnings[0].find("no luminous area"), std::string::npos);
}

TEST(Photometry, OpeningPolygonsFaceTheNadirWithTheirAreas)
{
  auto check = [](const Luminaire& l, double area)
  {
    const std::vector<Vec3> polygon = openingPolygon(l);
    Vec3 twice, centroid;
    for (std::size_t i = 0; i < polygon.size(); ++i)
    {
      twice += cross(polygon[i], polygon[(i + 1) % polygon.size()]);
      centroid += polygon[i];
      EXPECT_EQ(polygon[i].z, 0);
    }
    // The right-hand normal is the nadir -z, the first edge C = 0 (+x).
    EXPECT_NEAR(twice.z / 2, -area, 1e-12 * area);
    EXPECT_NEAR(polygon[1].y - polygon[0].y, 0, 1e-15);
    EXPECT_GT(polygon[1].x - polygon[0].x, 0);
    EXPECT_NEAR(length(centroid / double(polygon.size())), 0, 1e-15);
    double extentX = 0, extentY = 0;
    for (const Vec3& p : polygon)
    {
      extentX = std::max(extentX, std::abs(p.x));
      extentY = std::max(extentY, std::abs(p.y));
    }
    EXPECT_NEAR(2 * extentX, l.length, 0.01 * l.length);
    EXPECT_NEAR(2 * extentY, l.width, 0.01 * l.width);
  };
  Luminaire rectangle;
  rectangle.opening = OpeningShape::Rectangle;
  rectangle.length = 1.2;
  rectangle.width = 0.3;
  check(rectangle, 1.2 * 0.3);
  Luminaire ellipse = rectangle;
  ellipse.opening = OpeningShape::Ellipse;
  check(ellipse, Pi * 0.6 * 0.15);
  Luminaire none;
  EXPECT_NE(
    checks::errorOf([&] { openingPolygon(none); }).find("no luminous opening"), std::string::npos);
}

TEST(Photometry, BadEulumdatFilesNameTheLineAndField)
{
  const std::vector<double> gammas = degrees(0, 90, 30);
  const auto f = [](double g, double) { return 100 * cosPower(g, 1); };
  const std::string good = ldtFile(1, 90, gammas, f);
  ASSERT_NO_THROW(parseEulumdat(good, "good.ldt"));
  // Text after the intensities is named by its own line, past the blank ones.
  const std::size_t lineCount =
    static_cast<std::size_t>(std::count(good.begin(), good.end(), '\n'));
  const Luminaire trailing = parseEulumdat(good + "\n\nextra text\n", "trailing.ldt");
  ASSERT_EQ(trailing.warnings.size(), 1u);
  EXPECT_NE(trailing.warnings[0].find("trailing.ldt, line " + std::to_string(lineCount + 3) +
              ": ignored 1 line after the intensities"),
    std::string::npos)
    << trailing.warnings[0];
  auto line = [&](std::size_t number, const std::string& to)
  {
    std::vector<std::string> lines;
    std::istringstream in(good);
    for (std::string l; std::getline(in, l);)
    {
      lines.push_back(l);
    }
    lines.at(number - 1) = to;
    std::string text;
    for (const std::string& l : lines)
    {
      text += l + "\n";
    }
    return text;
  };
  auto error = [](const std::string& text)
  { return checks::errorOf([&] { parseEulumdat(text, "bad.ldt"); }); };
  std::string e = error(good.substr(0, good.rfind('\n', good.size() - 2) + 1));
  EXPECT_NE(e.find("bad.ldt, line 42"), std::string::npos) << e;
  EXPECT_NE(e.find("truncated"), std::string::npos) << e;
  e = error(line(3, "5"));
  EXPECT_NE(e.find("bad.ldt, line 3: the symmetry indicator Isym is 5"), std::string::npos) << e;
  e = error(line(4, "four"));
  EXPECT_NE(
    e.find("line 4: the number of C-planes Mc is 'four', not a finite number"), std::string::npos)
    << e;
  // Isym 2 stores 3 of the 4 planes: more intensities than the file has.
  e = error(line(3, "2"));
  EXPECT_NE(
    e.find("line 42: 4 C-planes and 4 intensities per plane need more lines"), std::string::npos)
    << e;
  // Mc = 3: the last C angle is read as the first gamma angle.
  e = error(line(4, "3"));
  EXPECT_NE(e.find("line 46: gamma angle 1 of 4 is 270 degrees: it must be within [0, 180]"),
    std::string::npos)
    << e;
  e = error(line(4, "6"));
  EXPECT_NE(e.find("need more lines"), std::string::npos) << e;
  e = error(line(6, "99999999"));
  EXPECT_NE(e.find("line 6: the number of intensities per C-plane Ng is 1e+08"), std::string::npos)
    << e;
  e = error(line(6, "9000"));
  EXPECT_NE(e.find("need more lines than the file has"), std::string::npos) << e;
  e = error(line(29, "0"));
  EXPECT_NE(e.find("line 29: the total luminous flux of lamps of set 1 is 0"), std::string::npos)
    << e;
  // A negative flux is no absolute photometry (that is a negative number of lamps).
  e = error(line(29, "-2000"));
  EXPECT_NE(
    e.find("line 29: the total luminous flux of lamps of set 1 is -2000 lm"), std::string::npos)
    << e;
  e = error(line(45, "80"));
  EXPECT_NE(
    e.find("line 45: C angle 3 of 4 is 80 degrees, not above the previous 90"), std::string::npos)
    << e;
  e = error(line(48, "inf"));
  EXPECT_NE(e.find("line 48: gamma angle 2 of 4 is 'inf'"), std::string::npos) << e;
  e = error(line(51, "-3"));
  EXPECT_NE(
    e.find("line 51: the intensity at C 0, gamma 0 (value 1 of 4) is -3"), std::string::npos)
    << e;
  // Isym 4 with C angles that do not put 90 at a quarter of the turn.
  std::string quarter = ldtFile(4, 90, gammas, f);
  const std::string planes = "\n0\n90\n180\n270\n";
  quarter.replace(quarter.find(planes), planes.size(), "\n0\n80\n180\n270\n");
  e = error(quarter);
  EXPECT_NE(
    e.find("line 44: C angle 2 is 80 degrees: symmetry Isym 4 needs 90 there"), std::string::npos)
    << e;
  EXPECT_NE(error("\n").find("the file ends"), std::string::npos);
}

TEST(Photometry, FilesAreReadOnlyWhenRegularAndSmall)
{
  TemporaryDirectory dir;
  const std::string fifo = (dir.path / "pipe.ies").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  checks::expectError([&] { readPhotometricFile(fifo); }, "not a regular file");
  std::filesystem::create_directory(dir.path / "folder.ldt");
  checks::expectError(
    [&] { readPhotometricFile((dir.path / "folder.ldt").string()); }, "not a regular file");
  checks::expectError(
    [&] { readPhotometricFile((dir.path / "missing.ies").string()); }, "missing.ies");
  checks::expectError(
    [&] { readPhotometricFile(dir.write("light.txt", "x")); }, "must end in .ies");
  const std::string big = dir.write("big.ies", "");
  std::filesystem::resize_file(big, 17 << 20);
  checks::expectError([&] { readPhotometricFile(big); }, "16 MiB");
  // The message names the file.
  checks::expectError([&]
    { readPhotometricFile(dir.write("broken.ies", "IESNA:LM-63-2002\nTILT=NONE\n1")); },
    "broken.ies: the file ends");
}
