#include "Photometry.h"

#include "Error.h"

#include <algorithm>
#include <cmath>
#include <sstream>

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

/// The integral of (g - a) sin g over [a, b].
double rampSinIntegral(double a, double b)
{
  return std::sin(b) - std::sin(a) - (b - a) * std::cos(b);
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
} // namespace

struct IntensityDistribution::Table
{
  double density(const Vec3&) const { return 0; }
  Vec3 sample(double, double) const { return Vec3(0, 0, 1); }
  double Flux = 0, MaximumDensity = 0;
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
  return this->Data->density(local);
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
  // cone, safeguarded Newton steps on the soft edge (its density is the integrand).
  const double target = u1 / (TwoPi * this->SpotNormalisation);
  const double cone = sinIntegral(0, this->HalfAngle);
  if (target <= cone || this->SoftEdge <= 0)
  {
    return directionOf(std::max(-1.0, 1 - std::min(target, cone)), TwoPi * u2);
  }
  double lo = this->HalfAngle, hi = std::min(Pi, this->HalfAngle + this->SoftEdge);
  double g = 0.5 * (lo + hi);
  for (int i = 0; i < 100; ++i)
  {
    const double f = spotPartialFlux(g, this->HalfAngle, this->SoftEdge) - target;
    if (f > 0)
    {
      hi = g;
    }
    else
    {
      lo = g;
    }
    const double slope = spotProfile(g, this->HalfAngle, this->SoftEdge) * std::sin(g);
    double next = slope > 0 ? g - f / slope : 0.5 * (lo + hi);
    if (!(next > lo && next < hi))
    {
      next = 0.5 * (lo + hi);
    }
    if (std::abs(next - g) < 1e-15 || hi - lo < 1e-15)
    {
      g = next;
      break;
    }
    g = next;
  }
  return directionOf(std::cos(g), TwoPi * u2);
}

double IntensityDistribution::intensity(const Vec3& local) const
{
  if (this->What == Kind::Tabulated)
  {
    return this->density(local) * this->flux();
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
  std::vector<double>, std::vector<double>, std::vector<double>)
{
  throw Error("tabulated intensity distributions are not implemented yet");
}

} // namespace mlr
