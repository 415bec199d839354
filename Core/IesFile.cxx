// The IES LM-63 reader (1986, 1991, 1995, 2002 and 2019 editions), photometric types C, B and A,
// the TILT=INCLUDE table and the luminous opening. Its keyword handling, multipliers, symmetries
// and opening shapes follow Radiance's ies2rad.
#include "Error.h"
#include "PhotometricParsing.h"
#include "Photometry.h"
#include "Plural.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

namespace mlr
{

namespace
{
using photometry::MaximumAngles;
using photometry::MaximumValues;

/// The numbers after the TILT line: whitespace or commas between them, across lines.
class Tokens
{
public:
  Tokens(const std::vector<std::string_view>& lines, std::size_t first, const std::string& name)
    : Lines(lines)
    , Line(first)
    , Name(name)
  {
  }

  /// The next number, called `field()` in messages (built only for them: tables are long).
  template <class Field>
  double numberFor(const Field& field)
  {
    const std::string_view token = this->next(field);
    double value;
    if (!photometry::parseNumber(token, value))
    {
      this->fail(field() + " is '" + std::string(token) + "', not a finite number");
    }
    return value;
  }

  double number(const std::string& field)
  {
    return this->numberFor([&] { return field; });
  }

  /// The number of tokens the rest of the text can hold at most.
  std::size_t capacity() const
  {
    std::size_t characters = 0;
    for (std::size_t l = this->Line; l < this->Lines.size(); ++l)
    {
      characters += this->Lines[l].size() + 1;
    }
    return characters / 2 + 1;
  }

  /// The next number, a whole one within [lowest, highest].
  std::size_t count(const std::string& field, std::size_t lowest, std::size_t highest)
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

  /// Throws naming the file and the line of the last token read.
  [[noreturn]] void fail(const std::string& what) const { throw Error(this->where() + what); }

  /// "name, line n: " of the last token read.
  std::string where() const
  {
    return this->Name + ", line " + std::to_string(this->TokenLine + 1) + ": ";
  }

  /// The values left after the table, and the line they start on.
  std::size_t remaining(std::size_t& line)
  {
    std::size_t n = 0;
    line = 0;
    while (this->advance())
    {
      if (n++ == 0)
      {
        line = this->Line + 1;
      }
      this->skipToken();
    }
    return n;
  }

private:
  /// Blanks, commas, and DOS's end-of-file mark (^Z), which old files end with, even right
  /// after their last value.
  static bool separator(char c)
  {
    return c == ' ' || c == '\t' || c == ',' || c == '\f' || c == '\v' || c == '\x1a';
  }

  /// Moves to the start of the next token; false at the end of the text.
  bool advance()
  {
    while (this->Line < this->Lines.size())
    {
      const std::string_view line = this->Lines[this->Line];
      while (this->Column < line.size() && separator(line[this->Column]))
      {
        ++this->Column;
      }
      if (this->Column < line.size())
      {
        return true;
      }
      ++this->Line;
      this->Column = 0;
    }
    return false;
  }

  std::string_view skipToken()
  {
    const std::string_view line = this->Lines[this->Line];
    const std::size_t start = this->Column;
    while (this->Column < line.size() && !separator(line[this->Column]))
    {
      ++this->Column;
    }
    return line.substr(start, this->Column - start);
  }

  template <class Field>
  std::string_view next(const Field& field)
  {
    if (!this->advance())
    {
      throw Error(this->Name + ": the file ends (after line " + std::to_string(this->Lines.size()) +
        ") before " + field() + ": it is truncated, or a count before it is too large");
    }
    this->TokenLine = this->Line;
    return this->skipToken();
  }

  const std::vector<std::string_view>& Lines;
  std::size_t Line, Column = 0, TokenLine = 0;
  const std::string& Name;
};

/// Reads `n` strictly ascending angles within [lowest, highest] degrees; `count` names the
/// field that gave `n`.
std::vector<double> readAngles(Tokens& tokens, std::size_t n, const std::string& what,
  const std::string& count, double lowest, double highest)
{
  std::vector<double> angles(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    auto field = [&] { return what + " " + std::to_string(i + 1) + " of " + std::to_string(n); };
    angles[i] = tokens.numberFor(field);
    if (angles[i] < lowest || angles[i] > highest)
    {
      tokens.fail(field() + " is " + formatNumber(angles[i]) + " degrees: it must be within [" +
        formatNumber(lowest) + ", " + formatNumber(highest) + "]");
    }
    if (i == 1 && !(angles[1] > angles[0]))
    {
      tokens.fail(field() + " is " + formatNumber(angles[1]) + " degrees, not above the first, " +
        formatNumber(angles[0]) + ": the angles must ascend strictly, from the lowest");
    }
    if (i > 1 && !(angles[i] > angles[i - 1]))
    {
      // A count too large reads the next block's values as angles, and they seldom ascend.
      tokens.fail(field() + " is " + formatNumber(angles[i]) + " degrees, not above the previous " +
        formatNumber(angles[i - 1]) + ": the angles must ascend strictly (if they end at " +
        formatNumber(angles[i - 1]) + ", " + count + " is " + std::to_string(i) + ", not " +
        std::to_string(n) + ")");
    }
  }
  return angles;
}

bool near(double a, double b)
{
  return std::abs(a - b) < 1e-6;
}

/// The largest difference between consecutive `angles`.
double largestStep(const std::vector<double>& angles)
{
  double step = 0;
  for (std::size_t i = 1; i < angles.size(); ++i)
  {
    step = std::max(step, angles[i] - angles[i - 1]);
  }
  return step;
}

constexpr double Degree = 3.14159265358979323846 / 180;

/// Mirrors a laterally symmetric table of types A and B (its first horizontal angle 0):
/// H -> -H, so that the planes run from -last to last.
void mirrorLaterally(std::vector<double>& horizontal, std::vector<double>& candela, std::size_t nV)
{
  std::vector<double> angles, values;
  for (std::size_t h = horizontal.size(); h-- > 1;)
  {
    angles.push_back(-horizontal[h]);
    values.insert(values.end(), candela.begin() + h * nV, candela.begin() + (h + 1) * nV);
  }
  angles.insert(angles.end(), horizontal.begin(), horizontal.end());
  values.insert(values.end(), candela.begin(), candela.end());
  horizontal = std::move(angles);
  candela = std::move(values);
}

/**
 * A type B table (angles in degrees, candela[h * vertical + v]) in the light's frame. Type B's
 * polar axis is the photometric horizontal, C = 0 (+x, along the opening's length), where
 * Radiance's ies2rad and source.cal put it (srcB_horiz = atan2(Dy, Dz), srcB_vert =
 * atan2(-Dx, Dz), D pointing into the source): the horizontal angle H turns a half-plane about
 * that axis from the nadir (H = 0) towards C = 270 (-y), and the vertical angle V rises within
 * that half-plane towards +x. So the direction of (H, V) is
 * cos V (0, -sin H, cos H) + sin V (1, 0, 0), and the table is a C-gamma table in its own axes:
 * gamma' = 90 - V from +x, C' = H - H0 from the half-plane H0. Interpolation stays bilinear in
 * the file's own angles.
 */
IntensityDistribution typeB(
  std::vector<double> vertical, std::vector<double> horizontal, std::vector<double> candela)
{
  const std::size_t nV = vertical.size();
  if (horizontal.size() == 1)
  {
    // One half-plane stands for a distribution symmetric about the beam: I(gamma) = I(V = gamma).
    const std::size_t zero =
      std::find_if(vertical.begin(), vertical.end(), [](double v) { return near(v, 0); }) -
      vertical.begin();
    if (zero == nV || nV - zero < 2)
    {
      throw Error(
        "a type B file with one horizontal angle is symmetric about its beam and needs the "
        "vertical angles 0 and above (0 to 90)");
    }
    std::vector<double> gammas, values;
    for (std::size_t v = zero; v < nV; ++v)
    {
      gammas.push_back(std::max(0.0, vertical[v]) * Degree);
      values.push_back(candela[v]);
    }
    return IntensityDistribution::tabulated(std::move(gammas), { 0.0 }, std::move(values));
  }
  if (near(horizontal.front(), 0))
  {
    // Laterally symmetric: H -> -H mirrors the half-planes about the vertical plane of the beam.
    mirrorLaterally(horizontal, candela, nV);
  }
  const double h0 = horizontal.front(), span = horizontal.back() - h0;
  if (span > 360 + 1e-6)
  {
    throw Error("the type B horizontal angles span " + formatNumber(span) +
      " degrees, more than the whole turn");
  }
  std::vector<double> gammas(nV), planes(horizontal.size()), values(candela.size());
  for (std::size_t v = 0; v < nV; ++v)
  {
    gammas[v] = (90 - vertical[nV - 1 - v]) * Degree;
  }
  for (std::size_t h = 0; h < horizontal.size(); ++h)
  {
    planes[h] = (horizontal[h] - h0) * Degree;
    for (std::size_t v = 0; v < nV; ++v)
    {
      values[h * nV + v] = candela[h * nV + nV - 1 - v];
    }
  }
  const double s = std::sin(h0 * Degree), c = std::cos(h0 * Degree);
  const PhotometricFrame axes{ { 0, -s, c }, { 0, -c, -s }, { 1, 0, 0 } };
  return IntensityDistribution::tabulatedInAxes(
    std::move(gammas), std::move(planes), std::move(values), axes, near(span, 360));
}

/**
 * A type A table (angles in degrees, candela[h * vertical + v]) in the light's frame. LM-63-2002
 * puts type A's planes through the vertical axis, as type C's, but counts its horizontal
 * angle H clockwise seen from above and its vertical angle V from the horizontal (V = -90 is
 * the nadir, H = 0 with V = 0 the photometric horizontal +x). So the direction of (H, V) is
 * cos V (cos H, -sin H, 0) + sin V (0, 0, -1): gamma = 90 + V and C = -H. The planes, taken in
 * ascending C (descending H), form a C-gamma table in axes turned to the last H, and the
 * interpolation stays bilinear in the file's own angles.
 */
IntensityDistribution typeA(
  std::vector<double> vertical, std::vector<double> horizontal, std::vector<double> candela)
{
  const std::size_t nV = vertical.size();
  std::vector<double> gammas(nV);
  for (std::size_t v = 0; v < nV; ++v)
  {
    gammas[v] = (90 + vertical[v]) * Degree;
  }
  if (horizontal.size() == 1)
  {
    // One plane stands for every H: rotationally symmetric about the vertical axis.
    return IntensityDistribution::tabulated(std::move(gammas), { 0.0 }, std::move(candela));
  }
  // From 0 to at most 180 is one side of a laterally symmetric table; a table from 0 over
  // more than half the turn is taken as given.
  if (near(horizontal.front(), 0) && horizontal.back() <= 180 + 1e-6)
  {
    mirrorLaterally(horizontal, candela, nV);
  }
  const double last = horizontal.back(), span = last - horizontal.front();
  if (span > 360 + 1e-6)
  {
    throw Error("the type A horizontal angles span " + formatNumber(span) +
      " degrees, more than the whole turn");
  }
  const std::size_t nH = horizontal.size();
  std::vector<double> planes(nH), values(candela.size());
  for (std::size_t i = 0; i < nH; ++i)
  {
    const std::size_t h = nH - 1 - i;
    planes[i] = (last - horizontal[h]) * Degree;
    std::copy(candela.begin() + h * nV, candela.begin() + (h + 1) * nV, values.begin() + i * nV);
  }
  const double s = std::sin(last * Degree), c = std::cos(last * Degree);
  // C' = 0 along C = -last; C' = 90 along C = 90 - last; the pole is the nadir.
  const PhotometricFrame axes{ { c, -s, 0 }, { s, c, 0 }, { 0, 0, 1 } };
  return IntensityDistribution::tabulatedInAxes(
    std::move(gammas), std::move(planes), std::move(values), axes, near(span, 360));
}

/**
 * The luminous opening from the signed width, length and height of an IES file (metres), by
 * the sign patterns of LM-63-1986/1991, 1995 and 2002/2019 (the 2019 edition keeps 2002's):
 * positive sizes are rectangular, negative ones round (diameters). Every shape is kept as its
 * outline seen from below (what a downlight shows its work plane), with a warning for those
 * whose sides or volume that outline leaves out.
 */
void readOpening(Luminaire& luminaire, double width, double length, double height, int year,
  const std::string& name)
{
  const int edition = year <= 1991 ? 1986 : year == 1995 ? 1995 : 2002;
  const double w = std::abs(width), l = std::abs(length), h = std::abs(height);
  auto sign = [](double x) { return x < 0 ? -1 : x > 0 ? 1 : 0; };
  const int sw = sign(width), sl = sign(length), sh = sign(height);
  auto is = [&](int a, int b, int c) { return sw == a && sl == b && sh == c; };
  auto set = [&](OpeningShape shape, const char* what, double alongX, double alongY)
  {
    luminaire.opening = shape;
    luminaire.openingName = what;
    luminaire.length = alongX;
    luminaire.width = alongY;
    luminaire.height = h;
  };
  auto outline = [&](const char* what, const char* from)
  {
    luminaire.openingWarnings.push_back(name + ": the luminous opening is a " + std::string(what) +
      ", emitted from its outline seen from below (" + from + ")");
  };
  luminaire.opening = OpeningShape::None;
  luminaire.openingName = "point";
  luminaire.width = w;
  luminaire.length = l;
  luminaire.height = h;
  if (is(0, 0, 0))
  {
    return;
  }
  if (is(1, 1, 0))
  {
    set(OpeningShape::Rectangle, "rectangle", l, w);
  }
  else if (sw >= 0 && sl >= 0 && sh > 0)
  {
    if (w > 0 && l > 0)
    {
      set(OpeningShape::Rectangle, "rectangle with luminous sides", l, w);
      outline("rectangle with luminous sides", "its bottom rectangle");
    }
    else
    {
      luminaire.openingName = "vertical rectangle";
      luminaire.openingWarnings.push_back(name +
        ": the luminous opening is a vertical rectangle, which has no extent seen from below: "
        "the luminaire is a point");
    }
  }
  else if (is(-1, 0, 0) || (edition == 2002 && is(-1, -1, 0) && std::abs(w - l) <= 1e-9 * w))
  {
    set(OpeningShape::Ellipse, "circle", w, w);
  }
  else if ((edition == 2002 && is(-1, -1, 0)) || (edition == 1986 && is(-1, 1, 0)))
  {
    set(OpeningShape::Ellipse, "ellipse", l, w);
  }
  else if (is(-1, 0, 1))
  {
    set(OpeningShape::Ellipse, "vertical cylinder", w, w);
    outline("vertical cylinder", "its bottom disc");
  }
  else if ((edition == 2002 && is(-1, -1, 1)) ||
    (edition == 1995 && (is(1, -1, 1) || is(-1, 1, 1))))
  {
    const bool round = std::abs(w - l) <= 1e-9 * w;
    set(OpeningShape::Ellipse, round ? "vertical cylinder" : "vertical elliptical cylinder", l, w);
    outline(luminaire.openingName.c_str(), round ? "its bottom disc" : "its bottom ellipse");
  }
  else if ((edition == 2002 && is(-1, -1, -1)) || (edition == 1995 && is(-1, 0, -1)) ||
    (edition == 1995 && (is(1, -1, -1) || is(-1, 1, -1))) || (edition == 1986 && is(-1, 1, 1)))
  {
    const double along = edition == 1995 && sl == 0 ? w : l;
    const bool round = std::abs(w - along) <= 1e-9 * w && std::abs(w - h) <= 1e-9 * w;
    set(OpeningShape::Ellipse, round ? "sphere" : "ellipsoid", along, w);
    outline(luminaire.openingName.c_str(), "its equator");
  }
  else if ((edition == 2002 && is(-1, 1, -1)) || (edition == 1995 && is(0, 1, -1)))
  {
    // Along the photometric horizontal: its length along x, its diameter across.
    set(OpeningShape::Rectangle, "horizontal cylinder along the photometric horizontal", l,
      w > 0 ? w : h);
    outline("horizontal cylinder", "the rectangle of its length by its diameter");
  }
  else if ((edition == 2002 && is(1, -1, -1)) || (edition == 1995 && is(1, 0, -1)))
  {
    set(OpeningShape::Rectangle, "horizontal cylinder across the photometric horizontal",
      l > 0 ? l : h, w);
    outline("horizontal cylinder", "the rectangle of its length by its diameter");
  }
  else if (edition == 2002 && is(0, -1, -1))
  {
    luminaire.openingName = "vertical disc facing the photometric horizontal";
    luminaire.openingWarnings.push_back(name +
      ": the luminous opening is a vertical disc, which has no extent seen from below: the "
      "luminaire is a point");
  }
  else
  {
    luminaire.openingName = "unknown shape";
    luminaire.openingWarnings.push_back(name + ": the luminous opening (width " +
      formatNumber(width) + ", length " + formatNumber(length) + ", height " +
      formatNumber(height) + " m) is none of LM-63-" + std::to_string(edition) +
      "'s shapes: the luminaire is a point");
  }
}
} // namespace

Luminaire parseIes(const std::string& text, const std::string& name)
{
  const std::vector<std::string_view> lines = photometry::splitLines(text);
  if (lines.empty())
  {
    throw Error(name +
      " is empty: an IES file starts with IESNA:LM-63-2002 (or another edition) "
      "and its TILT line");
  }
  Luminaire luminaire;

  // The edition: 1986 files have no such line, and there pfactor below still counts. Blank
  // lines before it are skipped, as ies2rad does: read as 1986, a 2019 file would take its
  // file generation type for that factor.
  int year = 1986;
  std::size_t firstLine = 0;
  while (firstLine + 1 < lines.size() && photometry::trim(lines[firstLine]).empty())
  {
    ++firstLine;
  }
  const std::string_view first = photometry::trim(lines[firstLine]);
  if (first.rfind("IESNA", 0) == 0 || first.rfind("IES:", 0) == 0)
  {
    if (first == "IESNA91")
    {
      year = 1991;
    }
    else if (first == "IESNA:LM-63-1995")
    {
      year = 1995;
    }
    else if (first == "IESNA:LM-63-2002")
    {
      year = 2002;
    }
    else if (first == "IES:LM-63-2019")
    {
      year = 2019;
    }
    else
    {
      year = 2002;
      luminaire.warnings.push_back(name + ", line " + std::to_string(firstLine + 1) +
        ": unknown edition '" + std::string(first) + "', read as LM-63-2002");
    }
  }

  // Keyword lines ([TEST], [MANUFAC], ...) up to the TILT line: they carry nothing the solve
  // needs. A 1986 label may start with the word, "TILTABLE BRACKET": the TILT line is the
  // word alone before its '='.
  auto isTiltLine = [](std::string_view line)
  {
    line = photometry::trim(line);
    return line.rfind("TILT", 0) == 0 &&
      (line.size() == 4 || !std::isalnum(static_cast<unsigned char>(line[4])));
  };
  std::size_t tiltLine = 0;
  while (tiltLine < lines.size() && !isTiltLine(lines[tiltLine]))
  {
    ++tiltLine;
  }
  if (tiltLine == lines.size())
  {
    throw Error(name +
      ": no TILT= line: an IES file gives TILT=NONE (or TILT=INCLUDE and its "
      "tilt table) after its keyword lines");
  }
  std::string_view tilt = photometry::trim(lines[tiltLine]);
  tilt.remove_prefix(4);
  tilt = photometry::trim(tilt);
  if (tilt.empty() || tilt.front() != '=')
  {
    throw Error(name + ", line " + std::to_string(tiltLine + 1) + ": the TILT line is '" +
      std::string(photometry::trim(lines[tiltLine])) + "': write TILT=NONE or TILT=INCLUDE");
  }
  tilt = photometry::trim(tilt.substr(1));
  Tokens tokens(lines, tiltLine + 1, name);
  if (tilt == "INCLUDE")
  {
    // The table is kept whole: the factor is the tilt of each pose's luminaire, which only the
    // light's poses know (Core/LuminaireTilt.h).
    const std::size_t geometry = tokens.count("the lamp-to-luminaire geometry (TILT=INCLUDE: 1 "
                                              "vertical lamp, 2 or 3 horizontal lamp)",
      1, 3);
    luminaire.tilt.geometry = static_cast<TiltTable::Geometry>(geometry);
    const std::size_t n = tokens.count("the number of tilt angles", 1, MaximumAngles);
    luminaire.tilt.angles =
      readAngles(tokens, n, "tilt angle", "the number of tilt angles", -360, 360);
    luminaire.tilt.factors.resize(n);
    for (std::size_t i = 0; i < n; ++i)
    {
      const std::string field =
        "tilt multiplying factor " + std::to_string(i + 1) + " of " + std::to_string(n);
      const double factor = tokens.number(field);
      if (factor < 0)
      {
        tokens.fail(field + " is " + formatNumber(factor) + ": factors must be >= 0");
      }
      luminaire.tilt.factors[i] = factor;
    }
  }
  else if (tilt != "NONE")
  {
    throw Error(name + ", line " + std::to_string(tiltLine + 1) + ": TILT=" + std::string(tilt) +
      " refers to a separate tilt file, which is not read: copy its data into the file with "
      "TILT=INCLUDE, or write TILT=NONE");
  }

  tokens.number("the number of lamps");
  // Not used: the flux is the table's integral, in relative and absolute photometry alike.
  // A value that is neither rated lumens nor -1 is named, not refused, as ies2rad reads it.
  const double lumensPerLamp = tokens.number("the lumens per lamp");
  if (!(lumensPerLamp > 0) && lumensPerLamp != -1)
  {
    luminaire.warnings.push_back(tokens.where() + "the lumens per lamp are " +
      formatNumber(lumensPerLamp) +
      ", neither rated lumens nor -1 (absolute photometry); the flux is the candela table's "
      "integral either way");
  }
  const double multiplier = tokens.number("the candela multiplier");
  if (!(multiplier > 0))
  {
    tokens.fail("the candela multiplier is " + formatNumber(multiplier) + ": it must be above 0");
  }
  const std::size_t nV = tokens.count("the number of vertical angles", 2, MaximumAngles);
  const std::size_t nH = tokens.count("the number of horizontal angles", 1, MaximumAngles);
  if (nV * nH > MaximumValues)
  {
    tokens.fail(std::to_string(nV) + " vertical by " + std::to_string(nH) +
      " horizontal angles make more than " + std::to_string(MaximumValues) + " candela values");
  }
  // Checked before allocating: the rest of the text must be able to hold the table.
  if (nV + nH + nV * nH > tokens.capacity())
  {
    tokens.fail(std::to_string(nV) + " vertical by " + std::to_string(nH) +
      " horizontal angles need " + std::to_string(nV * nH) +
      " candela values, more than the rest of the file holds: a count is wrong or the file is "
      "truncated");
  }
  const std::size_t type = tokens.count("the photometric type", 1, 3);
  const bool typeBFile = type == 2, typeAFile = type == 3;
  const std::size_t units = tokens.count("the units type (1 feet, 2 metres)", 1, 2);
  const double toMetres = units == 1 ? 0.3048 : 1;
  const double width = tokens.number("the width of the luminous opening");
  const double length = tokens.number("the length of the luminous opening");
  const double height = tokens.number("the height of the luminous opening");
  readOpening(luminaire, width * toMetres, length * toMetres, height * toMetres, year, name);
  const double ballast = tokens.number("the ballast factor");
  if (!(ballast > 0))
  {
    tokens.fail("the ballast factor is " + formatNumber(ballast) + ": it must be above 0");
  }
  double photometricFactor = 1;
  // The ballast-lamp photometric factor scales the candela in the 1986 and 1991 editions only:
  // 1995 and 2002 keep the field for future use, 2019 gives the file generation type there
  // (ies2rad likewise ignores it from 1995 on).
  if (year <= 1991)
  {
    photometricFactor = tokens.number("the ballast-lamp photometric factor");
    if (!(photometricFactor > 0))
    {
      tokens.fail("the ballast-lamp photometric factor is " + formatNumber(photometricFactor) +
        ": it must be above 0 (1 usually)");
    }
  }
  else
  {
    tokens.number(year == 2019 ? "the file generation type" : "the future use field");
  }
  tokens.number("the input watts");

  const bool typeC = !typeBFile && !typeAFile;
  const std::vector<double> vertical = readAngles(tokens, nV, "vertical angle",
    "the number of vertical angles", typeC ? 0 : -90, typeC ? 180 : 90);
  const std::vector<double> horizontal = readAngles(
    tokens, nH, "horizontal angle", "the number of horizontal angles", typeC ? 0 : -180, 360);
  photometry::PlaneSymmetry symmetry = photometry::PlaneSymmetry::None;
  const double h0 = horizontal.front(), h1 = horizontal.back();
  if (!typeC)
  {
    // typeB() and typeA() read their own symmetries: one angle, 0 to 90 (lateral), or as
    // given.
  }
  else if (nH == 1)
  {
    symmetry = photometry::PlaneSymmetry::Rotational;
  }
  else if (near(h0, 0) && near(h1, 90))
  {
    symmetry = photometry::PlaneSymmetry::Quadrants;
  }
  else if (near(h0, 0) && near(h1, 180))
  {
    symmetry = photometry::PlaneSymmetry::AboutC0C180;
  }
  else if (near(h0, 90) && near(h1, 270))
  {
    symmetry = photometry::PlaneSymmetry::AboutC90C270;
  }
  else if (!(near(h0, 0) && h1 > 180 && 360 - h1 <= largestStep(horizontal) + 1e-6))
  {
    // A full turn may leave out 360, the repeat of 0, but no more than one step of its own:
    // across a larger gap the intensities would be made up.
    tokens.fail("the horizontal angles run from " + formatNumber(h0) + " to " + formatNumber(h1) +
      " degrees: type C tables run 0 to 0, 90, 180 or 360 (or to 360 less one step), or 90 "
      "to 270");
  }

  const double scale = multiplier * ballast * photometricFactor;
  std::vector<double> candela(nV * nH);
  bool anyLight = false;
  for (std::size_t h = 0; h < nH; ++h)
  {
    for (std::size_t v = 0; v < nV; ++v)
    {
      auto field = [&]
      {
        return "the candela value at horizontal angle " + formatNumber(horizontal[h]) +
          ", vertical angle " + formatNumber(vertical[v]) + " (value " +
          std::to_string(h * nV + v + 1) + " of " + std::to_string(nV * nH) + ")";
      };
      const double value = tokens.numberFor(field);
      if (value < 0)
      {
        tokens.fail(field() + " is " + formatNumber(value) + ": candela must be >= 0");
      }
      candela[h * nV + v] = value * scale;
      anyLight = anyLight || value > 0;
    }
  }
  std::size_t extraLine;
  if (const std::size_t extra = tokens.remaining(extraLine))
  {
    luminaire.warnings.push_back(name + ", line " + std::to_string(extraLine) + ": ignored " +
      countOf(extra, "value") + " after the candela table");
  }
  if (!anyLight)
  {
    throw Error(name + ": every candela value is 0: the file describes no light");
  }
  try
  {
    luminaire.distribution = typeBFile ? typeB(vertical, horizontal, candela)
      : typeAFile                      ? typeA(vertical, horizontal, candela)
                  : photometry::fullTurn(vertical, horizontal, candela, symmetry);
  }
  catch (const Error& e)
  {
    throw Error(name + ": " + e.what());
  }
  luminaire.lumens = luminaire.distribution.flux();
  return luminaire;
}

} // namespace mlr
