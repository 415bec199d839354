// The EULUMDAT (.ldt) reader: one field a line in a fixed order, intensities in cd/klm.
#include "Error.h"
#include "PhotometricParsing.h"
#include "Photometry.h"
#include "Plural.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mlr
{

namespace
{
using photometry::MaximumAngles;
using photometry::MaximumValues;

/// The file's lines, read in order, each one field.
class Fields
{
public:
  Fields(const std::vector<std::string_view>& lines, const std::string& name)
    : Lines(lines)
    , Name(name)
  {
  }

  std::string_view text(const std::string& field)
  {
    return this->next([&] { return field; });
  }

  /// The next line as a number, called `field()` in messages (built only for them).
  template <class Field>
  double numberFor(const Field& field)
  {
    const std::string_view token = photometry::trim(this->next(field));
    double value;
    bool ok = photometry::parseNumber(token, value);
    if (!ok && token.find(',') != std::string_view::npos &&
      token.find('.') == std::string_view::npos)
    {
      // Some programs write a decimal comma.
      std::string point(token);
      std::replace(point.begin(), point.end(), ',', '.');
      ok = photometry::parseNumber(point, value);
    }
    if (!ok)
    {
      this->fail(field() + " is '" + std::string(token) + "', not a finite number");
    }
    return value;
  }

  double number(const std::string& field)
  {
    return this->numberFor([&] { return field; });
  }

  /// The next line, a whole number within [lowest, highest].
  std::size_t count(const std::string& field, long lowest, long highest)
  {
    const double value = this->number(field);
    if (!(value >= static_cast<double>(lowest) && value <= static_cast<double>(highest)) ||
      value != std::floor(value))
    {
      this->fail(field + " is " + formatNumber(value) + ": it must be a whole number from " +
        std::to_string(lowest) + " to " + std::to_string(highest));
    }
    return static_cast<std::size_t>(value);
  }

  /// Throws naming the file and the line last read.
  [[noreturn]] void fail(const std::string& what) const
  {
    throw Error(this->Name + ", line " + std::to_string(this->Line) + ": " + what);
  }

  std::size_t left() const { return this->Lines.size() - this->Line; }

  /// The lines left after the intensities that are not blank, and the first of them
  /// (counted from 1).
  std::size_t remaining(std::size_t& firstLine) const
  {
    std::size_t n = 0;
    for (std::size_t l = this->Line; l < this->Lines.size(); ++l)
    {
      if (!photometry::trim(this->Lines[l]).empty())
      {
        firstLine = n == 0 ? l + 1 : firstLine;
        ++n;
      }
    }
    return n;
  }

  std::size_t line() const { return this->Line; }

private:
  template <class Field>
  std::string_view next(const Field& field)
  {
    if (this->Line >= this->Lines.size())
    {
      throw Error(this->Name + ": the file ends (after line " + std::to_string(this->Lines.size()) +
        ") before " + field() + ": it is truncated, or a count before it is too large");
    }
    return this->Lines[this->Line++];
  }

  const std::vector<std::string_view>& Lines;
  std::size_t Line = 0; ///< the number of lines read: the last one's number in messages
  const std::string& Name;
};
} // namespace

Luminaire parseEulumdat(const std::string& text, const std::string& name)
{
  const std::vector<std::string_view> lines = photometry::splitLines(text);
  if (lines.empty())
  {
    throw Error(name +
      " is empty: a EULUMDAT file has one field a line, from the company "
      "identification on");
  }
  Luminaire luminaire;
  Fields fields(lines, name);
  fields.text("the company identification (line 1)");
  fields.count("the type indicator Ityp", 0, 3);
  const std::size_t isym = fields.count("the symmetry indicator Isym", 0, 4);
  const std::size_t mc = fields.count("the number of C-planes Mc", 1, MaximumAngles);
  // The planes a symmetry stores must fall on the table's own C angles.
  if ((isym == 2 && mc % 2 != 0) || ((isym == 3 || isym == 4) && mc % 4 != 0))
  {
    fields.fail("the number of C-planes Mc is " + std::to_string(mc) + ": symmetry Isym " +
      std::to_string(isym) + " needs a multiple of " + (isym == 2 ? "2" : "4"));
  }
  fields.number("the distance between C-planes Dc");
  const std::size_t ng = fields.count("the number of intensities per C-plane Ng", 2, MaximumAngles);
  fields.number("the distance between intensities Dg");
  fields.text("the measurement report number");
  fields.text("the luminaire name");
  fields.text("the luminaire number");
  fields.text("the file name");
  fields.text("the date and user");
  const double bodyLength = fields.number("the length or diameter of the luminaire (mm)");
  const double bodyWidth = fields.number("the width of the luminaire (mm)");
  fields.number("the height of the luminaire (mm)");
  // The luminous area: its length along C0-C180, its width (0 for a round one) along
  // C90-C270, its heights towards C0, C90, C180 and C270.
  double areaLength = fields.number("the length or diameter of the luminous area (mm)");
  double areaWidth = fields.number("the width of the luminous area (mm)");
  double areaHeight = 0;
  for (const char* plane : { "C0", "C90", "C180", "C270" })
  {
    areaHeight = std::max(areaHeight,
      std::abs(
        fields.number(std::string("the height of the luminous area in ") + plane + " (mm)")));
  }
  if (areaLength == 0 && areaWidth == 0 && bodyLength != 0)
  {
    // No luminous area: the luminaire's own outline is the nearest thing to it.
    areaLength = bodyLength;
    areaWidth = bodyWidth;
    luminaire.openingWarnings.push_back(
      name + ": no luminous area is given; an area luminaire emits from the luminaire's outline");
  }
  luminaire.length = std::abs(areaLength) / 1000;
  luminaire.width = (areaWidth == 0 ? std::abs(areaLength) : std::abs(areaWidth)) / 1000;
  luminaire.height = areaHeight / 1000;
  if (luminaire.length > 0 && luminaire.width > 0)
  {
    luminaire.opening = areaWidth == 0 ? OpeningShape::Ellipse : OpeningShape::Rectangle;
    luminaire.openingName = areaWidth == 0 ? "circle" : "rectangle";
    if (areaHeight > 0)
    {
      luminaire.openingName += " with luminous sides";
      luminaire.openingWarnings.push_back(
        name + ": the luminous area has luminous sides, emitted from its outline seen from below");
    }
  }
  fields.number("the downward flux fraction DFF (%)");
  fields.number("the light output ratio LORL (%)");
  double conversion = fields.number("the conversion factor for luminous intensities");
  if (conversion < 0)
  {
    fields.fail("the conversion factor for luminous intensities is " + formatNumber(conversion) +
      ": it must be >= 0 (1 usually; 0 is read as 1)");
  }
  if (conversion == 0)
  {
    conversion = 1;
  }
  fields.number("the tilt of the luminaire during measurement");
  const std::size_t sets = fields.count("the number of standard sets of lamps n", 1, 20);
  // Each set's six fields come together, set after set, as files from luminaire makers and
  // other readers have them. The intensities are per 1000 lm of the first set's total flux
  // (the luminaire's own flux for absolute photometry, where its number of lamps is
  // negative); the flux already counts every lamp of the set.
  double lampFlux = 0;
  for (std::size_t i = 0; i < sets; ++i)
  {
    const std::string set = "set " + std::to_string(i + 1);
    fields.number("the number of lamps of " + set);
    fields.text("the type of lamps of " + set);
    const double flux = fields.number("the total luminous flux of lamps of " + set + " (lm)");
    if (i == 0)
    {
      // Only the number of lamps is negative for absolute photometry; the flux is then the
      // luminaire's own, still positive.
      lampFlux = flux;
      if (!(lampFlux > 0))
      {
        fields.fail("the total luminous flux of lamps of set 1 is " + formatNumber(flux) +
          " lm: the cd/klm intensities need it above 0 (for absolute photometry, give the "
          "luminaire's flux and a negative number of lamps)");
      }
    }
    fields.text("the colour appearance of " + set);
    fields.text("the colour rendering group of " + set);
    fields.number("the wattage including ballast of " + set + " (W)");
  }
  if (sets > 1)
  {
    luminaire.warnings.push_back(name + ": " + std::to_string(sets) +
      " sets of lamps, read as alternative equipments: the intensities are scaled to the "
      "first set's flux, not to their sum");
  }
  for (int k = 0; k < 10; ++k)
  {
    fields.number("direct ratio " + std::to_string(k + 1) + " of 10");
  }

  // The C angles of the whole turn, then the gamma angles, then the stored planes.
  std::size_t first = 0, stored = mc;
  photometry::PlaneSymmetry symmetry = photometry::PlaneSymmetry::None;
  switch (isym)
  {
    case 1:
      stored = 1;
      symmetry = photometry::PlaneSymmetry::Rotational;
      break;
    case 2:
      stored = mc / 2 + 1;
      symmetry = photometry::PlaneSymmetry::AboutC0C180;
      break;
    case 3:
      first = 3 * mc / 4;
      stored = mc / 2 + 1;
      symmetry = photometry::PlaneSymmetry::AboutC90C270;
      break;
    case 4:
      stored = mc / 4 + 1;
      symmetry = photometry::PlaneSymmetry::Quadrants;
      break;
    default:
      break;
  }
  if (stored * ng > MaximumValues || mc + ng + stored * ng > fields.left())
  {
    fields.fail(std::to_string(mc) + " C-planes and " + std::to_string(ng) +
      " intensities per plane need more lines than the file has: a count is wrong or the file is "
      "truncated");
  }
  auto readAngles = [&](std::size_t n, const char* what, const char* count, double highest)
  {
    std::vector<double> angles(n);
    for (std::size_t i = 0; i < n; ++i)
    {
      auto field = [&]
      { return std::string(what) + " " + std::to_string(i + 1) + " of " + std::to_string(n); };
      angles[i] = fields.numberFor(field);
      if (angles[i] < 0 || angles[i] > highest)
      {
        fields.fail(field() + " is " + formatNumber(angles[i]) +
          " degrees: it must be within [0, " + formatNumber(highest) + "]");
      }
      if (i > 0 && !(angles[i] > angles[i - 1]))
      {
        // A count too large reads the next block's values as angles, and they seldom ascend.
        fields.fail(field() + " is " + formatNumber(angles[i]) +
          " degrees, not above the previous " + formatNumber(angles[i - 1]) +
          ": the angles must ascend strictly (if they end at " + formatNumber(angles[i - 1]) +
          ", " + count + " is " + std::to_string(i) + ", not " + std::to_string(n) + ")");
      }
    }
    return angles;
  };
  const std::size_t cLine = fields.line() + 1;
  const std::vector<double> cAngles = readAngles(mc, "C angle", "the number of C-planes Mc", 360);
  auto expect = [&](std::size_t index, double angle)
  {
    if (std::abs(cAngles[index] - angle) > 1e-6)
    {
      throw Error(name + ", line " + std::to_string(cLine + index) + ": C angle " +
        std::to_string(index + 1) + " is " + formatNumber(cAngles[index]) +
        " degrees: symmetry Isym " + std::to_string(isym) + " needs " + formatNumber(angle) +
        " there");
    }
  };
  if (isym != 1)
  {
    expect(0, 0);
  }
  if (isym == 2)
  {
    expect(mc / 2, 180);
  }
  if (isym == 3 || isym == 4)
  {
    expect(mc / 4, 90);
  }
  if (isym == 3)
  {
    expect(3 * mc / 4, 270);
  }
  const std::vector<double> gammas =
    readAngles(ng, "gamma angle", "the number of intensities per C-plane Ng", 180);

  std::vector<double> planes(stored), candela(stored * ng);
  for (std::size_t p = 0; p < stored; ++p)
  {
    // Isym 3 stores C270 up to C90 through C0: past the turn, 360 more.
    const std::size_t index = (first + p) % mc;
    planes[p] = cAngles[index] + (first + p >= mc ? 360 : 0);
  }
  const double scale = lampFlux / 1000 * conversion;
  bool anyLight = false;
  for (std::size_t p = 0; p < stored; ++p)
  {
    for (std::size_t g = 0; g < ng; ++g)
    {
      auto field = [&]
      {
        return "the intensity at C " + formatNumber(std::fmod(planes[p], 360)) + ", gamma " +
          formatNumber(gammas[g]) + " (value " + std::to_string(p * ng + g + 1) + " of " +
          std::to_string(stored * ng) + ")";
      };
      const double value = fields.numberFor(field);
      if (value < 0)
      {
        fields.fail(field() + " is " + formatNumber(value) + " cd/klm: intensities must be >= 0");
      }
      candela[p * ng + g] = value * scale;
      anyLight = anyLight || value > 0;
    }
  }
  std::size_t extraLine = 0;
  if (const std::size_t extra = fields.remaining(extraLine))
  {
    luminaire.warnings.push_back(name + ", line " + std::to_string(extraLine) + ": ignored " +
      countOf(extra, "line") + " after the intensities");
  }
  if (!anyLight)
  {
    throw Error(name + ": every intensity is 0: the file describes no light");
  }
  try
  {
    luminaire.distribution = photometry::fullTurn(gammas, planes, candela, symmetry);
  }
  catch (const Error& e)
  {
    throw Error(name + ": " + e.what());
  }
  luminaire.lumens = luminaire.distribution.flux();
  return luminaire;
}

} // namespace mlr
