// What the IES and EULUMDAT readers share: strict numbers, the bounds on their counts and the
// expansion of a symmetric table to the whole turn. Private to Core.
#pragma once

#include "Photometry.h"

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace mlr
{
namespace photometry
{

/// Bounds on a file's counts, checked before anything is allocated: real files have a few
/// hundred angles and some ten thousand values.
constexpr std::size_t MaximumAngles = 10000;
constexpr std::size_t MaximumValues = 10000000;

/// The lines of a text without their line ends (LF, CRLF or CR) and without a UTF-8 byte
/// order mark; line k is number k + 1 in messages.
std::vector<std::string_view> splitLines(std::string_view text);

/// The whole of `token` as a finite number ("1", "-1", "+2.5", "1e3"); false for text,
/// trailing characters, NaN or infinity.
bool parseNumber(std::string_view token, double& value);

/// `text` without its leading and trailing blanks.
std::string_view trim(std::string_view text);

/// The symmetry a file stores its planes with (the C angles of `planesDegrees` below).
enum class PlaneSymmetry
{
  None,         ///< the planes cover the whole turn
  Rotational,   ///< one plane stands for every C
  AboutC0C180,  ///< planes 0..180, mirrored by C -> 360 - C
  AboutC90C270, ///< planes 90..270 (or 270..450), mirrored by C -> 180 - C
  Quadrants     ///< planes 0..90, mirrored about both
};

/// The distribution of a table stored with `symmetry` (angles in degrees, candela[p * gammas
/// + g]), its planes expanded to the whole turn.
IntensityDistribution fullTurn(const std::vector<double>& gammasDegrees,
  const std::vector<double>& planesDegrees, const std::vector<double>& candela,
  PlaneSymmetry symmetry);

} // namespace photometry
} // namespace mlr
