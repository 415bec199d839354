#include "Photometry.h"

#include "Error.h"
#include "PhotometricParsing.h"
#include "RegularFile.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <sstream>
#include <utility>

namespace mlr
{

namespace
{
constexpr double Pi = 3.14159265358979323846;
constexpr double TwoPi = 2 * Pi;

/// The unit direction of vertical angle gamma (from the nadir +z) in the plane C (from +x
/// towards +y).
Vec3 directionOf(double cosGamma, double c)
{
  const double sinGamma = std::sqrt(std::max(0.0, 1 - cosGamma * cosGamma));
  return Vec3(sinGamma * std::cos(c), sinGamma * std::sin(c), cosGamma);
}

double gammaOf(const Vec3& local)
{
  return std::acos(std::clamp(local.z / length(local), -1.0, 1.0));
}

/// The integral of sin over [a, b], without the cancellation of cos a - cos b for close angles.
double sinIntegral(double a, double b)
{
  return 2 * std::sin(0.5 * (a + b)) * std::sin(0.5 * (b - a));
}

/// The integral of (g - a) sin g over [a, b]. The closed form sin b - sin a - (b - a) cos b
/// cancels to nothing for close angles, so short intervals sum the Taylor series of
/// sin(a + t) under t dt instead.
double rampSinIntegral(double a, double b)
{
  const double h = b - a;
  if (h > 0.05)
  {
    return std::sin(b) - std::sin(a) - h * std::cos(b);
  }
  const double derivatives[4] = { std::sin(a), std::cos(a), -std::sin(a), -std::cos(a) };
  double sum = 0, power = h * h, factorial = 1;
  for (int n = 0; n < 8; ++n)
  {
    sum += derivatives[n % 4] * power / (factorial * (n + 2));
    power *= h;
    factorial *= n + 1;
  }
  return sum;
}

/// The spot's relative intensity at gamma: 1 in the cone, linear to 0 over the soft edge.
double spotProfile(double gamma, double halfAngle, double softEdge)
{
  if (gamma <= halfAngle)
  {
    return 1;
  }
  if (softEdge <= 0 || gamma >= halfAngle + softEdge)
  {
    return 0;
  }
  return 1 - (gamma - halfAngle) / softEdge;
}

/// The integral of spotProfile(g) sin g over [0, gamma] (gamma within [0, pi]).
double spotPartialFlux(double gamma, double halfAngle, double softEdge)
{
  const double inner = std::min(gamma, halfAngle);
  double f = sinIntegral(0, inner);
  if (gamma > halfAngle && softEdge > 0)
  {
    const double b = std::min(gamma, halfAngle + softEdge);
    f += sinIntegral(halfAngle, b) - rampSinIntegral(halfAngle, b) / softEdge;
  }
  return f;
}

/**
 * The gamma in [g0, g1] where the integral of ((1 - s) a + s b) sin(gamma), s the fraction
 * (gamma - g0) / (g1 - g0), reaches the fraction u of its total: the inverse CDF of an
 * intensity linear in gamma (a table's cell at a given C, a spot's soft edge). Newton steps,
 * kept inside a shrinking bracket.
 */
double invertLinearSinCdf(double g0, double g1, double a, double b, double u)
{
  const double h = g1 - g0, s0 = std::sin(g0), c0 = std::cos(g0);
  // The closed forms cancel for short intervals: those take the series.
  const bool closed = h >= 1e-3;
  auto cdf = [&](double g, double sg, double cg)
  {
    const double ramp = (closed ? sg - s0 - (g - g0) * cg : rampSinIntegral(g0, g)) / h;
    return a * ((closed ? c0 - cg : sinIntegral(g0, g)) - ramp) + b * ramp;
  };
  const double target = u * cdf(g1, std::sin(g1), std::cos(g1));
  if (!(target > 0))
  {
    return g0 + u * h;
  }
  // The start: the answer for sin(gamma) constant over the interval, where the CDF is a
  // quadratic in s (solved as the C marginal's, scaled so that no square overflows).
  const double largest = std::max(a, b), m0 = a / largest, m1 = b / largest;
  const double s =
    u * (m0 + m1) / (m0 + std::sqrt(std::max(0.0, m0 * m0 + u * (m1 * m1 - m0 * m0))));
  double lo = g0, hi = g1, g = std::clamp(g0 + s * h, g0, g1);
  for (int i = 0; i < 60 && hi - lo > 1e-13; ++i)
  {
    const double sg = std::sin(g), cg = std::cos(g);
    const double f = cdf(g, sg, cg) - target;
    if (f == 0)
    {
      break;
    }
    (f > 0 ? hi : lo) = g;
    const double slope = (a + (b - a) * (g - g0) / h) * sg;
    double next = slope > 0 ? g - f / slope : 0.5 * (lo + hi);
    if (!(next > lo && next < hi))
    {
      next = 0.5 * (lo + hi);
    }
    // 1e-13 rad: the CDF's rounding moves the root by about that much, and no sample sees it.
    const bool converged = std::abs(next - g) < 1e-13;
    g = next;
    if (converged)
    {
      break;
    }
  }
  return g;
}
} // namespace

/**
 * The bilinear table and its sampling. A cell spans two consecutive vertical angles and two
 * consecutive planes (the last C cell wraps from the last plane to the first plus 2 pi). Its
 * flux, the integral of the bilinear intensity times sin(gamma), has a closed form; the cells'
 * cumulative fluxes pick a cell, and inside it the inverse CDF is exact: the marginal in C of
 * a bilinear intensity is linear (a quadratic to invert), and the conditional in gamma,
 * (a + b s) sin(gamma), is inverted by safeguarded Newton steps on its closed-form CDF. So
 * sample() draws exactly density() = intensity() / flux(), up to rounding: no residual
 * mismatch between the two, and estimators that divide by density() stay unbiased.
 */
struct IntensityDistribution::Table
{
  std::vector<double> Gammas, Planes, Candela;
  /// Cumulative flux of the cells, C cell major: cell (k, g) is k * (gammas - 1) + g.
  std::vector<double> Cumulative;
  double Flux = 0, MaximumDensity = 0;
  std::size_t LastCell = 0; ///< the last cell with flux (where u1 rounding to 1 lands)
  /// The table's own axes in the light's frame (identity unless Rotated), and whether its
  /// planes wrap around the turn (Closed) or cover only [first, last], 0 beyond.
  PhotometricFrame Axes{ { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  bool Rotated = false, Closed = true;

  /// C cell k (one per plane, the last one wrapping, of zero width when the planes end at
  /// 2 pi): its first plane, its last plane and its start and width (radians).
  void cCell(std::size_t k, std::size_t& p0, std::size_t& p1, double& c0, double& w) const
  {
    const std::size_t n = this->Planes.size();
    p0 = k;
    p1 = k + 1 < n ? k + 1 : 0;
    c0 = this->Planes[k];
    w = k + 1 < n ? this->Planes[k + 1] - c0
                  : (this->Closed ? std::max(0.0, this->Planes[0] + TwoPi - c0) : 0.0);
  }

  double value(std::size_t plane, std::size_t g) const
  {
    return this->Candela[plane * this->Gammas.size() + g];
  }

  /// The weights of the cell's lower and upper vertical angle in its flux: the integrals of
  /// (1 - s) sin(gamma) and s sin(gamma) over the cell, s its fraction of the cell.
  void gammaWeights(std::size_t g, double& w0, double& w1) const
  {
    const double a = this->Gammas[g], b = this->Gammas[g + 1];
    w1 = rampSinIntegral(a, b) / (b - a);
    w0 = sinIntegral(a, b) - w1;
  }

  /// The candela in a unit direction of the light's frame.
  double intensity(const Vec3& light) const
  {
    const Vec3 local = this->Rotated ? this->Axes.toLocal(light) : light;
    const double gamma = gammaOf(local);
    if (gamma < this->Gammas.front() || gamma > this->Gammas.back())
    {
      return 0;
    }
    const std::size_t g = std::min<std::size_t>(
      std::upper_bound(this->Gammas.begin(), this->Gammas.end(), gamma) - this->Gammas.begin() - 1,
      this->Gammas.size() - 2);
    double c = std::atan2(local.y, local.x);
    if (c < 0)
    {
      c += TwoPi;
    }
    const std::size_t n = this->Planes.size();
    std::size_t k = n - 1;
    if (!this->Closed && (c < this->Planes[0] || c > this->Planes[n - 1]))
    {
      return 0;
    }
    if (c < this->Planes[0])
    {
      c += TwoPi;
    }
    else if (c < this->Planes[n - 1])
    {
      k = std::upper_bound(this->Planes.begin(), this->Planes.end(), c) - this->Planes.begin() - 1;
    }
    std::size_t p0, p1;
    double c0, w;
    this->cCell(k, p0, p1, c0, w);
    const double t = w > 0 ? std::clamp((c - c0) / w, 0.0, 1.0) : 0;
    const double s =
      std::clamp((gamma - this->Gammas[g]) / (this->Gammas[g + 1] - this->Gammas[g]), 0.0, 1.0);
    return (1 - t) * ((1 - s) * this->value(p0, g) + s * this->value(p0, g + 1)) +
      t * ((1 - s) * this->value(p1, g) + s * this->value(p1, g + 1));
  }

  Vec3 sample(double u1, double u2) const
  {
    const std::size_t nG = this->Gammas.size() - 1;
    const double x = u1 * this->Flux;
    std::size_t cell = std::upper_bound(this->Cumulative.begin(), this->Cumulative.end(), x) -
      this->Cumulative.begin();
    cell = std::min(cell, this->LastCell);
    const double before = cell > 0 ? this->Cumulative[cell - 1] : 0;
    const double r = std::clamp((x - before) / (this->Cumulative[cell] - before), 0.0, 1.0);
    const std::size_t k = cell / nG, g = cell % nG;
    std::size_t p0, p1;
    double c0, w, w0, w1;
    this->cCell(k, p0, p1, c0, w);
    this->gammaWeights(g, w0, w1);

    // C: the marginal density is linear in t, from m0 to m1; its CDF is a quadratic, solved
    // in the form that does not cancel, with m0 and m1 scaled so that no square overflows.
    double m0 = this->value(p0, g) * w0 + this->value(p0, g + 1) * w1;
    double m1 = this->value(p1, g) * w0 + this->value(p1, g + 1) * w1;
    const double largest = std::max(m0, m1);
    m0 /= largest;
    m1 /= largest;
    const double t = std::clamp(
      r * (m0 + m1) / (m0 + std::sqrt(std::max(0.0, m0 * m0 + r * (m1 * m1 - m0 * m0)))), 0.0, 1.0);
    double c = c0 + t * w;
    if (c >= TwoPi)
    {
      c -= TwoPi;
    }

    // gamma: the intensity along the cell at this C is a (1 - s) + b s.
    const double a = (1 - t) * this->value(p0, g) + t * this->value(p1, g);
    const double b = (1 - t) * this->value(p0, g + 1) + t * this->value(p1, g + 1);
    const double gamma = invertLinearSinCdf(this->Gammas[g], this->Gammas[g + 1], a, b, u2);
    const Vec3 local = directionOf(std::cos(gamma), c);
    return this->Rotated ? this->Axes.toWorld(local) : local;
  }
};

PhotometricFrame PhotometricFrame::fromNadir(const Vec3& nadir, const Vec3& zeroPlane)
{
  const double n = length(nadir), p = length(zeroPlane);
  if (!isFinite(nadir) || !(n > 0) || !std::isfinite(n))
  {
    throw Error("the photometric nadir must be a finite, non-zero direction");
  }
  if (!isFinite(zeroPlane) || !(p > 0) || !std::isfinite(p))
  {
    throw Error("the photometric C = 0 direction must be a finite, non-zero direction");
  }
  PhotometricFrame frame;
  frame.z = nadir / n;
  const Vec3 x = zeroPlane / p - frame.z * dot(zeroPlane / p, frame.z);
  const double xl = length(x);
  if (!(xl > 1e-9))
  {
    throw Error("the photometric C = 0 direction is parallel to the nadir: give a direction "
                "across it (the luminaire's length axis)");
  }
  frame.x = x / xl;
  frame.y = cross(frame.x, frame.z);
  return frame;
}

IntensityDistribution IntensityDistribution::lambertian()
{
  return IntensityDistribution();
}

IntensityDistribution IntensityDistribution::spot(double halfAngle, double softEdge)
{
  if (!(halfAngle > 0 && halfAngle <= Pi))
  {
    std::ostringstream s;
    s << "the spot's half angle is " << halfAngle << " rad: it must be in (0, pi]";
    throw Error(s.str());
  }
  if (!(softEdge >= 0) || !std::isfinite(softEdge))
  {
    std::ostringstream s;
    s << "the spot's soft edge is " << softEdge << " rad: it must be finite and >= 0";
    throw Error(s.str());
  }
  IntensityDistribution d;
  d.What = Kind::Spot;
  d.HalfAngle = halfAngle;
  d.SoftEdge = softEdge;
  d.SpotNormalisation = 1 / (TwoPi * spotPartialFlux(Pi, halfAngle, softEdge));
  return d;
}

double IntensityDistribution::density(const Vec3& local) const
{
  switch (this->What)
  {
    case Kind::Lambertian:
      return std::max(0.0, local.z / length(local)) / Pi;
    case Kind::Spot:
      return this->SpotNormalisation * spotProfile(gammaOf(local), this->HalfAngle, this->SoftEdge);
    case Kind::Tabulated:
      break;
  }
  return this->Data->intensity(local) / this->Data->Flux;
}

Vec3 IntensityDistribution::sample(double u1, double u2) const
{
  switch (this->What)
  {
    case Kind::Lambertian:
      // Malley's method: a uniform point of the disk lifted to the hemisphere.
      return directionOf(std::sqrt(1 - u1), TwoPi * u2);
    case Kind::Spot:
      break;
    case Kind::Tabulated:
      return this->Data->sample(u1, u2);
  }
  // The CDF in gamma is 2 pi normalisation times spotPartialFlux: closed form inside the
  // cone, then the soft edge's.
  const double target = u1 / (TwoPi * this->SpotNormalisation);
  const double cone = sinIntegral(0, this->HalfAngle);
  const double edge = spotPartialFlux(Pi, this->HalfAngle, this->SoftEdge) - cone;
  if (target <= cone || !(edge > 0))
  {
    return directionOf(std::max(-1.0, 1 - std::min(target, cone)), TwoPi * u2);
  }
  // The soft edge, cut at the zenith, is linear in gamma from 1 down to `end`.
  const double top = std::min(Pi, this->HalfAngle + this->SoftEdge);
  const double end = 1 - (top - this->HalfAngle) / this->SoftEdge;
  const double g =
    invertLinearSinCdf(this->HalfAngle, top, 1, end, std::clamp((target - cone) / edge, 0.0, 1.0));
  return directionOf(std::cos(g), TwoPi * u2);
}

double IntensityDistribution::intensity(const Vec3& local) const
{
  if (this->What == Kind::Tabulated)
  {
    return this->Data->intensity(local);
  }
  return this->density(local);
}

double IntensityDistribution::flux() const
{
  return this->What == Kind::Tabulated ? this->Data->Flux : 1;
}

double IntensityDistribution::maximumDensity() const
{
  switch (this->What)
  {
    case Kind::Lambertian:
      return 1 / Pi;
    case Kind::Spot:
      return this->SpotNormalisation;
    case Kind::Tabulated:
      break;
  }
  return this->Data->MaximumDensity;
}

bool IntensityDistribution::isLambertian() const
{
  return this->What == Kind::Lambertian;
}

IntensityDistribution IntensityDistribution::tabulated(
  std::vector<double> gammas, std::vector<double> planes, std::vector<double> candela)
{
  return tabulatedInAxes(std::move(gammas), std::move(planes), std::move(candela),
    PhotometricFrame{ { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } }, true);
}

IntensityDistribution IntensityDistribution::tabulatedInAxes(std::vector<double> gammas,
  std::vector<double> planes, std::vector<double> candela, const PhotometricFrame& axes,
  bool closed)
{
  if (gammas.size() < 2 || planes.empty())
  {
    throw Error("an intensity table needs at least two vertical angles and one plane (it has " +
      std::to_string(gammas.size()) + " and " + std::to_string(planes.size()) + ")");
  }
  if (candela.size() / planes.size() != gammas.size() || candela.size() % planes.size() != 0)
  {
    throw Error("an intensity table of " + std::to_string(gammas.size()) + " vertical angles and " +
      std::to_string(planes.size()) + " planes needs " +
      std::to_string(gammas.size() * planes.size()) + " candela values, not " +
      std::to_string(candela.size()));
  }
  // Degrees converted to radians may overshoot pi or 2 pi by an ulp.
  constexpr double slack = 1e-9;
  auto checkAngles = [](std::vector<double>& angles, double top, const char* what)
  {
    for (std::size_t i = 0; i < angles.size(); ++i)
    {
      double& angle = angles[i];
      if (angle > top && angle <= top + slack)
      {
        angle = top;
      }
      if (angle < 0 && angle >= -slack)
      {
        angle = 0;
      }
      if (!std::isfinite(angle) || angle < 0 || angle > top || (i > 0 && !(angle > angles[i - 1])))
      {
        std::ostringstream s;
        s << "the intensity table's " << what << " " << i << " is " << angle
          << " rad: they must be finite, strictly ascending and within [0, " << top << "]";
        throw Error(s.str());
      }
    }
  };
  checkAngles(gammas, Pi, "vertical angle");
  checkAngles(planes, TwoPi, "plane angle");
  double largest = 0;
  for (std::size_t i = 0; i < candela.size(); ++i)
  {
    if (!std::isfinite(candela[i]) || candela[i] < 0)
    {
      std::ostringstream s;
      s << "the intensity table's value " << i << " is " << candela[i]
        << " cd: intensities must be finite and >= 0";
      throw Error(s.str());
    }
    largest = std::max(largest, candela[i]);
  }

  auto table = std::make_shared<Table>();
  table->Axes = axes;
  table->Rotated = !(axes.x.x == 1 && axes.y.y == 1 && axes.z.z == 1);
  table->Closed = closed;
  table->Gammas = std::move(gammas);
  table->Planes = std::move(planes);
  table->Candela = std::move(candela);
  const std::size_t nG = table->Gammas.size() - 1, nC = table->Planes.size();
  table->Cumulative.resize(nG * nC);
  double sum = 0;
  for (std::size_t k = 0; k < nC; ++k)
  {
    std::size_t p0, p1;
    double c0, w;
    table->cCell(k, p0, p1, c0, w);
    for (std::size_t g = 0; g < nG; ++g)
    {
      double w0, w1;
      table->gammaWeights(g, w0, w1);
      const double cell = 0.5 * w *
        ((table->value(p0, g) + table->value(p1, g)) * w0 +
          (table->value(p0, g + 1) + table->value(p1, g + 1)) * w1);
      if (cell > 0)
      {
        table->LastCell = k * nG + g;
      }
      sum += cell;
      table->Cumulative[k * nG + g] = sum;
    }
  }
  if (!(sum > 0))
  {
    throw Error("the intensity table emits no flux: give some positive candela values");
  }
  if (!(sum <= MaximumLightPower))
  {
    std::ostringstream s;
    s << "the intensity table emits " << sum << " lm, more than " << MaximumLightPower
      << " lm: its candela values (times the multiplier) are far too large";
    throw Error(s.str());
  }
  table->Flux = sum;
  table->MaximumDensity = largest / sum;

  IntensityDistribution d;
  d.What = Kind::Tabulated;
  d.Data = std::move(table);
  return d;
}

double TiltTable::factor(double degrees) const
{
  if (this->angles.empty())
  {
    return 1;
  }
  const std::size_t n = this->angles.size();
  const std::size_t above =
    std::upper_bound(this->angles.begin(), this->angles.end(), degrees) - this->angles.begin();
  if (above == 0)
  {
    return this->factors.front();
  }
  if (above == n)
  {
    return this->factors.back();
  }
  const double t =
    (degrees - this->angles[above - 1]) / (this->angles[above] - this->angles[above - 1]);
  return (1 - t) * this->factors[above - 1] + t * this->factors[above];
}

bool TiltTable::varies() const
{
  return std::any_of(this->factors.begin(), this->factors.end(),
    [&](double f) { return f != this->factors.front(); });
}

std::vector<Vec3> openingPolygon(const Luminaire& luminaire)
{
  const double a = luminaire.length / 2, b = luminaire.width / 2;
  if (luminaire.opening == OpeningShape::None || !(a > 0) || !(b > 0))
  {
    throw Error("the luminaire has no luminous opening to emit from (its " + luminaire.openingName +
      " has no extent seen from below)");
  }
  if (luminaire.opening == OpeningShape::Rectangle)
  {
    // Clockwise seen from above, so that the right-hand normal is the nadir -z.
    return { { -a, b, 0 }, { a, b, 0 }, { a, -b, 0 }, { -a, -b, 0 } };
  }
  // A regular polygon stretched to the ellipse, of the ellipse's area (the polygon of radius r
  // has (n / 2) r^2 sin(2 pi / n)), its first edge along +x: vertices at pi / 2 + pi / n and on,
  // clockwise.
  constexpr int n = 48;
  const double scale = std::sqrt(Pi / (0.5 * n * std::sin(TwoPi / n)));
  std::vector<Vec3> polygon;
  for (int i = 0; i < n; ++i)
  {
    const double phi = Pi / 2 + Pi / n - TwoPi * i / n;
    polygon.emplace_back(a * scale * std::cos(phi), b * scale * std::sin(phi), 0);
  }
  return polygon;
}

namespace photometry
{

std::vector<std::string_view> splitLines(std::string_view text)
{
  if (text.size() >= 3 && text.substr(0, 3) == "\xEF\xBB\xBF")
  {
    text.remove_prefix(3);
  }
  std::vector<std::string_view> lines;
  std::size_t start = 0;
  for (std::size_t i = 0; i < text.size(); ++i)
  {
    if (text[i] == '\n' || text[i] == '\r')
    {
      lines.push_back(text.substr(start, i - start));
      if (text[i] == '\r' && i + 1 < text.size() && text[i + 1] == '\n')
      {
        ++i;
      }
      start = i + 1;
    }
  }
  if (start < text.size())
  {
    lines.push_back(text.substr(start));
  }
  return lines;
}

std::string_view trim(std::string_view text)
{
  auto blank = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  while (!text.empty() && blank(text.front()))
  {
    text.remove_prefix(1);
  }
  while (!text.empty() && blank(text.back()))
  {
    text.remove_suffix(1);
  }
  return text;
}

bool parseNumber(std::string_view token, double& value)
{
  if (!token.empty() && token.front() == '+')
  {
    token.remove_prefix(1);
  }
  if (token.empty() || token.front() == '+')
  {
    return false;
  }
  // from_chars, unlike strtod, ignores the locale: a file reads the same everywhere.
  const auto result = std::from_chars(token.data(), token.data() + token.size(), value);
  return result.ec == std::errc() && result.ptr == token.data() + token.size() &&
    std::isfinite(value);
}

IntensityDistribution fullTurn(const std::vector<double>& gammasDegrees,
  const std::vector<double>& planesDegrees, const std::vector<double>& candela,
  PlaneSymmetry symmetry)
{
  constexpr double toRadians = Pi / 180;
  std::vector<double> gammas(gammasDegrees.size());
  for (std::size_t g = 0; g < gammas.size(); ++g)
  {
    gammas[g] = gammasDegrees[g] * toRadians;
  }
  if (symmetry == PlaneSymmetry::Rotational)
  {
    return IntensityDistribution::tabulated(std::move(gammas), { 0.0 }, candela);
  }
  // Each mirror is C -> sign C + offset; the image planes take their source's values.
  std::vector<std::pair<double, double>> mirrors{ { 1, 0 } };
  switch (symmetry)
  {
    case PlaneSymmetry::AboutC0C180:
      mirrors.push_back({ -1, 360 });
      break;
    case PlaneSymmetry::AboutC90C270:
      mirrors.push_back({ -1, 180 });
      break;
    case PlaneSymmetry::Quadrants:
      mirrors.insert(mirrors.end(), { { -1, 180 }, { 1, 180 }, { -1, 360 } });
      break;
    default:
      break;
  }
  struct Image
  {
    double angle;
    std::size_t mirror, source;
  };
  std::vector<Image> images;
  for (std::size_t m = 0; m < mirrors.size(); ++m)
  {
    for (std::size_t p = 0; p < planesDegrees.size(); ++p)
    {
      double c = std::fmod(mirrors[m].first * planesDegrees[p] + mirrors[m].second, 360.0);
      if (c < 0)
      {
        c += 360;
      }
      images.push_back({ c, m, p });
    }
  }
  // Where images coincide (the mirror planes themselves, 0 and 360), the file's own plane wins.
  std::sort(images.begin(), images.end(),
    [](const Image& a, const Image& b)
    {
      return a.angle < b.angle ||
        (a.angle == b.angle &&
          (a.mirror < b.mirror || (a.mirror == b.mirror && a.source < b.source)));
    });
  const std::size_t nG = gammas.size();
  std::vector<double> planes, values;
  double last = -1;
  for (std::size_t i = 0; i < images.size(); ++i)
  {
    if (images[i].angle - last < 1e-9)
    {
      continue;
    }
    last = images[i].angle;
    planes.push_back(images[i].angle * toRadians);
    values.insert(values.end(), candela.begin() + images[i].source * nG,
      candela.begin() + (images[i].source + 1) * nG);
  }
  return IntensityDistribution::tabulated(std::move(gammas), std::move(planes), std::move(values));
}

} // namespace photometry

namespace
{
const FileKind PhotometricFile{ "photometric file", "an .ies or .ldt file", 16u << 20,
  "the 16 MiB any real IES or EULUMDAT file needs" };
} // namespace

Luminaire readPhotometricFile(const std::string& path)
{
  const std::size_t dot = path.find_last_of('.');
  std::string extension = dot == std::string::npos ? "" : path.substr(dot + 1);
  for (char& c : extension)
  {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  if (extension == "ies")
  {
    return parseIes(readRegularFile(path, PhotometricFile), path);
  }
  if (extension == "ldt")
  {
    return parseEulumdat(readRegularFile(path, PhotometricFile), path);
  }
  throw Error("the photometric file " + path + " must end in .ies (IES LM-63) or .ldt (EULUMDAT)");
}

} // namespace mlr
