// The sky as a light: the CIE and Perez luminance models, normalised to a diffuse horizontal
// irradiance, tabulated on a fine grid of the upper hemisphere so that the paths' direction
// density is known exactly (Documentation/Method.md, "The sky").
#pragma once

#include "Vec3.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace mlr
{

enum class SkyModel
{
  Uniform,     ///< constant radiance
  CieOvercast, ///< L = Lz (1 + 2 cos t) / 3 (CIE S 011 type 16)
  CieClear,    ///< CIE S 011 type 12, a = -1, b = -0.32, c = 10, d = -3, e = 0.45
  Perez        ///< Perez all-weather (1993) from the direct normal and diffuse horizontal
};

/// "uniform", "cie-overcast", "cie-clear" or "perez"; throws mlr::Error naming the choices.
SkyModel parseSkyModel(const std::string& name);
std::string skyModelName(SkyModel model);

/// One frame's sky: the unit direction towards the sun (any, also below the horizon, for the
/// models that ignore it), the diffuse horizontal irradiance E_dh, the direct normal
/// irradiance (W/m^2) and the day of the year (1 to 366; 0 when the date is not known, then
/// day 150, as gendaylit takes it), which set the extraterrestrial irradiance. Only the Perez
/// model reads the last two.
struct SkyFrame
{
  Vec3 sun{ 0, 0, 1 };
  double diffuseHorizontal = 0;
  double directNormal = 0;
  int dayOfYear = 0;
};

/**
 * The relative luminance of a model, in the frame whose z is the zenith: any positive scale,
 * the normalisation is the Sky's. `sun` is the unit direction towards the sun in that frame.
 */
class SkyDistribution
{
public:
  SkyDistribution(SkyModel model, const Vec3& sun, double diffuseHorizontal, double directNormal,
    int dayOfYear = 0);
  /// At the unit direction `towardsSky` (z >= 0).
  double operator()(const Vec3& towardsSky) const
  {
    return (*this)(towardsSky, this->gradation(towardsSky.z));
  }
  /// The same, with gradation(towardsSky.z) given: it depends on the zenith angle alone, so
  /// that a table of a ring's directions computes it once.
  double operator()(const Vec3& towardsSky, double gradation) const;
  /// The factor of the clear and Perez models that depends on the zenith angle alone.
  double gradation(double cosZenith) const;
  /// The Perez sky clearness epsilon and brightness Delta (1 and 0 for the other models).
  double clearness() const { return this->Clearness; }
  double brightness() const { return this->Brightness; }

private:
  SkyModel Model;
  Vec3 Sun;
  double Coefficients[5] = { 0, 0, 0, 0, 0 };
  double Clearness = 1, Brightness = 0;
};

/// The Perez (1990) luminous efficacies (lm/W) of the sky's diffuse and the sun's direct
/// light, with 2 cm of precipitable water, as gendaylit has them.
struct DaylightEfficacy
{
  double diffuse = 0, direct = 0;
};
DaylightEfficacy perezEfficacy(const SkyFrame& frame, const Vec3& up);

/**
 * A sky over several frames, with the zenith along `up`. Each frame's model is tabulated on
 * Rings x Sectors cells (equal steps of zenith angle and azimuth), each cell holding the mean
 * of the model over it, and scaled so that an unobstructed horizontal surface receives
 * exactly E_dh of that frame. Frames that are the same sky share one position: a sky that
 * does not change has one and is solved once.
 */
class Sky
{
public:
  static constexpr int Rings = 60;
  static constexpr int Sectors = 120;
  static constexpr std::size_t Cells = std::size_t(Rings) * Sectors;

  /// Throws mlr::Error on an E_dh below 0 or not finite, a day of the year outside 0 to 366,
  /// a zero `up`, or no frames. The positions' tables are built on `threads` workers (0:
  /// every core), the same bits for any count: a year of hourly Perez skies is half a
  /// billion evaluations of the model.
  Sky(SkyModel model, const Vec3& up, const std::vector<SkyFrame>& frames, int threads = 0);

  SkyModel model() const { return this->Model; }
  const Vec3& up() const { return this->Up; }
  std::size_t frameCount() const { return this->FrameCount; }
  /// The sky of frames [first, first + count) (the frames of a chunk, Chunks.h).
  Sky slice(std::size_t first, std::size_t count) const;
  /// The positions: 1 when every frame is the same sky, else one per frame.
  std::size_t positions() const { return this->Lambda.size(); }
  /// The integral of the radiance over the sky's solid angle (W/m^2) at `position`.
  double integral(std::size_t position) const { return this->Lambda[position]; }
  /// The tabulated radiance (W/m^2/sr) at `position` towards the unit direction `towardsSky`
  /// (0 below the horizon).
  double radiance(std::size_t position, const Vec3& towardsSky) const;
  /// The direction density (per sr) of `position`'s paths: radiance / integral.
  double density(std::size_t position, std::size_t cell) const
  {
    return this->Density[cell * this->positions() + position];
  }
  /// density(j, cell) of every position j, side by side.
  const double* densities(std::size_t cell) const
  {
    return this->Density.data() + cell * this->positions();
  }
  /// The cell of a direction above the horizon, or Cells below it.
  std::size_t cell(const Vec3& towardsSky) const;
  /// A direction drawn with density(position, .) from two uniform numbers and a third.
  Vec3 sample(std::size_t position, double u0, double u1, double u2) const;
  /// The model's own radiance, not tabulated, normalised the same way (for checks).
  double modelRadiance(std::size_t position, const Vec3& towardsSky) const;
  /// The positions whose Perez fit is negative over the whole sky, drawn as a uniform sky of
  /// the same E_dh instead (as Radiance's gendaymtx does).
  std::vector<std::size_t> uniformInsteadFrames() const;
  /// The bytes of the tables: about 115 KB per position.
  std::uint64_t allocatedBytes() const;

private:
  Vec3 toLocal(const Vec3& v) const
  {
    return { dot(v, this->T), dot(v, this->B), dot(v, this->Up) };
  }
  /// The model `position` is drawn with: Model, or Uniform where UniformInstead says so.
  SkyDistribution distribution(std::size_t position) const;

  SkyModel Model;
  Vec3 Up, T, B;
  std::size_t FrameCount = 0;
  std::vector<SkyFrame> Frames; ///< one per position
  std::vector<double> Lambda;
  std::vector<double> Scale;                ///< radiance per unit of the model's relative luminance
  std::vector<double> Density;              ///< cell-major: all positions of a cell side by side
  std::vector<double> Cdf;                  ///< position-major
  std::vector<std::uint8_t> UniformInstead; ///< per position
};

} // namespace mlr
