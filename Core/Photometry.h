// Luminous intensity distributions: how a luminaire spreads its flux over directions, in its
// own frame, and the photometric files (IES LM-63, EULUMDAT) that describe real ones.
#pragma once

#include "Vec3.h"

#include <memory>
#include <string>
#include <vector>

namespace mlr
{

/// The largest light power (W per channel) and luminous flux (lm) taken, however given:
/// LightPower, LightFluxLumens or a photometric file's own flux. The outputs are single
/// precision (at most 3.4e38), which leaves them 8 orders of magnitude for a surface near a
/// light of this power.
constexpr double MaximumLightPower = 1e30;

/**
 * A light's own photometric frame. z is the nadir (gamma = 0): the emission normal of an area
 * light, minus the up direction for a point light. x is C = 0: the light's first edge, +x for
 * a point light. y = x cross z is C = 90, so that C runs counter-clockwise seen from behind
 * the light (from above for a downlight), as LM-63 type C and EULUMDAT define it. The frame
 * turns with the light's poses.
 */
struct PhotometricFrame
{
  Vec3 x{ 1, 0, 0 }, y{ 0, 1, 0 }, z{ 0, 0, -1 };

  /// The frame of nadir `nadir` and C = 0 towards `zeroPlane` (made orthogonal to the nadir).
  /// Throws mlr::Error when they are parallel or either is zero.
  static PhotometricFrame fromNadir(const Vec3& nadir, const Vec3& zeroPlane);

  Vec3 toWorld(const Vec3& local) const
  {
    return this->x * local.x + this->y * local.y + this->z * local.z;
  }
  Vec3 toLocal(const Vec3& world) const
  {
    return Vec3(dot(world, this->x), dot(world, this->y), dot(world, this->z));
  }
};

/**
 * A luminous intensity distribution I(gamma, C) over the whole sphere, in the light's own
 * photometric frame (local directions: z the nadir, x the C = 0 plane).
 *
 * The solver needs it normalised: density() is f(omega) = I(omega) / Phi (1/sr), which
 * integrates to 1 over the sphere, so that a path leaving in a direction drawn by sample()
 * carries Phi / N whatever the distribution, and the reuse kernel of a point light at x_k is
 * p_k(y) = f_k(y - x_k) cos(theta_y) / r^2. The Lambertian distribution of an area light is
 * f = cos(gamma) / pi on the emitting side.
 *
 * Values are immutable and cheap to copy (the table is shared).
 */
class IntensityDistribution
{
public:
  /// f = max(0, cos gamma) / pi: a diffuse emitter.
  static IntensityDistribution lambertian();

  /// Uniform intensity inside the cone of `halfAngle` (radians, in (0, pi]) about the nadir,
  /// falling linearly to zero over `softEdge` (radians, >= 0) beyond it. Throws mlr::Error
  /// for angles out of range.
  static IntensityDistribution spot(double halfAngle, double softEdge = 0);

  /**
   * A table: candela at the vertical angles `gammas` (radians, strictly ascending, within
   * [0, pi]) in the horizontal planes `planes` (radians, strictly ascending, within
   * [0, 2 pi], covering the whole turn after the caller's symmetry expansion: the last plane
   * may be 2 pi or the table wraps from the last to the first), `candela[p * gammas.size()
   * + g]`. Intensity is interpolated bilinearly in (gamma, C) and zero outside the gamma
   * range. Throws mlr::Error for empty, unordered, negative or non-finite tables, or a table
   * with no flux.
   */
  static IntensityDistribution tabulated(
    std::vector<double> gammas, std::vector<double> planes, std::vector<double> candela);

  /**
   * A table as tabulated() takes it, but in its own axes: `axes` gives the table's x (C = 0),
   * y (C = 90) and z (gamma = 0) as directions of the light's frame, so that a table whose
   * polar axis is not the nadir (IES type B) keeps its bilinear interpolation in its own
   * angles. With `closed` false the planes cover only [first, last] and the intensity is 0
   * beyond them; with it true the last cell wraps to the first plane as in tabulated().
   */
  static IntensityDistribution tabulatedInAxes(std::vector<double> gammas,
    std::vector<double> planes, std::vector<double> candela, const PhotometricFrame& axes,
    bool closed);

  /// f(omega) in 1/sr for a unit direction in the light's frame.
  double density(const Vec3& local) const;

  /// A unit direction in the light's frame drawn with density f, from two uniform numbers
  /// in [0, 1) (the table's CDF with the table's interpolation; exact inversion for the
  /// analytic kinds).
  Vec3 sample(double u1, double u2) const;

  /// The intensity as given (candela for a table, f for the analytic kinds) in a direction.
  double intensity(const Vec3& local) const;

  /// The integral of intensity() over the sphere: lumens for a table.
  double flux() const;

  /// The largest density over the sphere (bounds the kernel, e.g. for a spot's cone).
  double maximumDensity() const;

  bool isLambertian() const;

  struct Table; ///< the tabulated data and its sampling tables

private:
  enum class Kind
  {
    Lambertian,
    Spot,
    Tabulated
  };
  Kind What = Kind::Lambertian;
  double HalfAngle = 0, SoftEdge = 0, SpotNormalisation = 0;
  std::shared_ptr<const Table> Data;
};

/**
 * LM-63's TILT=INCLUDE table: a factor on the luminaire's output for the angle it is tilted by
 * from its photometered position (aimed straight down), linear between the tabulated angles
 * and clamped at the ends. How the tilt is measured depends on how the lamp sits in the
 * luminaire (the geometry); see Core/LuminaireTilt.h.
 */
struct TiltTable
{
  /// LM-63's lamp-to-luminaire geometry.
  enum class Geometry
  {
    /// 1: the lamp's axis is the luminaire's nadir axis (vertical, base up or down, when the
    /// luminaire is aimed straight down).
    Vertical = 1,
    /// 2: the lamp lies along the photometric horizontal (C0-C180, x) and stays horizontal
    /// when the luminaire turns about that axis: it only rolls about its own axis.
    HorizontalAlongC0 = 2,
    /// 3: the lamp lies across it (along C90-C270, y) and tilts when the luminaire turns
    /// about the photometric horizontal.
    HorizontalAlongC90 = 3
  };
  Geometry geometry = Geometry::Vertical;
  std::vector<double> angles;  ///< degrees, strictly ascending (empty: TILT=NONE)
  std::vector<double> factors; ///< one per angle, >= 0

  bool empty() const { return this->angles.empty(); }
  /// The factor at `degrees`: linear between the tabulated angles, the end factor beyond.
  double factor(double degrees) const;
  /// True when the factors differ.
  bool varies() const;
};

/// The shapes of LM-63-2002's and EULUMDAT's luminous openings an area luminaire emits from:
/// the opening seen from below, along the nadir.
enum class OpeningShape
{
  None,      ///< no opening given (a point), or one with no extent seen from below
  Rectangle, ///< length (x) by width (y)
  Ellipse    ///< diameters length (x) and width (y): a circle when they are equal
};

/// A luminaire read from a photometric file.
struct Luminaire
{
  IntensityDistribution distribution;
  /// The luminous flux the file's photometry gives (lm): the integral of its candela, times
  /// the candela multiplier and ballast factor, before any tilt factor (which is the pose's).
  double lumens = 0;
  /// The luminous opening in metres (0 when not given): an area luminaire emits from it.
  /// length runs along C0-C180 (x of the frame), width along C90-C270 (y): the extents of the
  /// opening seen from below (a round opening has its diameter in both); height is its
  /// vertical extent (luminous sides, a cylinder's or a sphere's height).
  double width = 0, length = 0, height = 0;
  OpeningShape opening = OpeningShape::None;
  /// The file's own name of the shape ("rectangle", "circle", "vertical cylinder", ...; "point"
  /// when none is given), for messages.
  std::string openingName = "point";
  /// TILT=INCLUDE's table (empty for TILT=NONE and EULUMDAT).
  TiltTable tilt;
  /// What was read but not applied (values after the table, an unknown edition, several lamp
  /// sets), one sentence each naming the file.
  std::vector<std::string> warnings;
  /// What the opening leaves out (a shape emitted from its outline seen from below, one with no
  /// extent from below, a missing luminous area): for a light that emits from the opening
  /// only.
  std::vector<std::string> openingWarnings;
};

/**
 * The emitting polygon of a luminaire's opening in the light's own frame of a point light:
 * centred on the origin in the plane z = 0, facing -z (its nadir), its first edge along +x
 * (C = 0), so that an area light made of it has the photometric frame of a point light. A
 * rectangle is itself; an ellipse a 48-gon of its area. Throws mlr::Error when the shape is
 * None.
 */
std::vector<Vec3> openingPolygon(const Luminaire& luminaire);

/// Reads an IES LM-63 (.ies) or EULUMDAT (.ldt) file, chosen by its extension. Throws
/// mlr::Error naming the file, line and field to fix.
Luminaire readPhotometricFile(const std::string& path);

/// The IES LM-63-1995/2002/2019 text of a file called `name` (for messages).
Luminaire parseIes(const std::string& text, const std::string& name);

/// The EULUMDAT text of a file called `name` (for messages).
Luminaire parseEulumdat(const std::string& text, const std::string& name);

} // namespace mlr
