// PLY, ASCII and binary (readPly).
#include "RadiositySceneFormats.h"

#include "SceneText.h"

#include "vtkCellArray.h"
#include "vtkPoints.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace mlr::scenefile
{

namespace
{
enum class PlyFormat
{
  Ascii,
  BinaryLittle,
  BinaryBig
};

/// Bytes of one value of a PLY scalar type, 0 for a name PLY does not know.
int plyBytes(const std::string& type)
{
  static const std::map<std::string, int> types = { { "char", 1 }, { "uchar", 1 }, { "int8", 1 },
    { "uint8", 1 }, { "short", 2 }, { "ushort", 2 }, { "int16", 2 }, { "uint16", 2 }, { "int", 4 },
    { "uint", 4 }, { "int32", 4 }, { "uint32", 4 }, { "float", 4 }, { "float32", 4 },
    { "double", 8 }, { "float64", 8 } };
  const auto found = types.find(type);
  return found == types.end() ? 0 : found->second;
}

bool plyIsFloat(const std::string& type)
{
  return type == "float" || type == "float32" || type == "double" || type == "float64";
}

bool plyIsSigned(const std::string& type)
{
  return type == "char" || type == "int8" || type == "short" || type == "int16" || type == "int" ||
    type == "int32";
}

struct PlyProperty
{
  std::string name, type;
  bool list = false;
  std::string countType;
};

struct PlyElement
{
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
  int find(const std::string& property) const
  {
    for (std::size_t i = 0; i < this->properties.size(); ++i)
    {
      if (this->properties[i].name == property)
      {
        return static_cast<int>(i);
      }
    }
    return -1;
  }
};

/// Reads the values of a PLY body, ASCII or binary, with the file named in errors.
class PlyValues
{
public:
  PlyValues(std::istream& in, PlyFormat format, const std::string& path)
    : In(in)
    , Format(format)
    , Path(path)
  {
  }

  double read(const std::string& type, const std::string& what)
  {
    if (this->Format == PlyFormat::Ascii)
    {
      std::string word;
      double value = 0;
      if (!(this->In >> word))
      {
        this->truncated(what);
      }
      if (!parseNumber(word, value))
      {
        throw FileError("the PLY file " + named(this->Path) + ": '" + printable(word) + "' (" +
          what + ") is not a finite number");
      }
      return value;
    }
    const int bytes = plyBytes(type);
    unsigned char raw[8];
    if (!this->In.read(reinterpret_cast<char*>(raw), bytes))
    {
      this->truncated(what);
    }
    const bool little = this->Format == PlyFormat::BinaryLittle;
    std::uint64_t bits = 0;
    for (int i = 0; i < bytes; ++i)
    {
      bits |= static_cast<std::uint64_t>(raw[little ? i : bytes - 1 - i]) << (8 * i);
    }
    double value = 0;
    if (type == "float" || type == "float32")
    {
      const auto narrow = static_cast<std::uint32_t>(bits);
      float f;
      std::memcpy(&f, &narrow, 4);
      value = f;
    }
    else if (type == "double" || type == "float64")
    {
      std::memcpy(&value, &bits, 8);
    }
    else if (plyIsSigned(type))
    {
      const std::uint64_t sign = std::uint64_t(1) << (8 * bytes - 1);
      value = static_cast<double>(
        static_cast<std::int64_t>((bits ^ sign)) - static_cast<std::int64_t>(sign));
    }
    else
    {
      value = static_cast<double>(bits);
    }
    if (!std::isfinite(value))
    {
      throw FileError(
        "the PLY file " + named(this->Path) + ": " + what + " is not a finite number");
    }
    return value;
  }

private:
  [[noreturn]] void truncated(const std::string& what)
  {
    throw FileError("the PLY file " + named(this->Path) + " ends before " + what +
      ": it is truncated or its header counts more elements than it holds");
  }
  std::istream& In;
  PlyFormat Format;
  std::string Path;
};

/// A colour value as a reflectance: 8-bit integers /255, 16-bit /65535, floats as they are.
double plyColour(double value, const std::string& type)
{
  if (plyIsFloat(type))
  {
    return value;
  }
  return value / (plyBytes(type) == 1 ? 255.0 : 65535.0);
}
} // namespace

Scene readPly(
  const std::string& path, const Warn& warn, const Progress& progress, const MemoryBudget& budget)
{
  std::ifstream in = openFile(path, "PLY file");
  ProgressPoll poll(progress, 0.0, 0.9);
  auto fail = [&](const std::string& problem)
  { throw FileError("the PLY file " + named(path) + " " + problem); };
  std::string line;
  if (!std::getline(in, line) || trim(line) != "ply")
  {
    fail("is not a PLY file: it does not start with 'ply'");
  }
  std::vector<PlyElement> elements;
  PlyFormat format = PlyFormat::Ascii;
  bool hasFormat = false, ended = false;
  std::size_t unknownLines = 0;
  std::string firstUnknown;
  for (std::size_t number = 2; !ended && std::getline(in, line); ++number)
  {
    if (number > 10000)
    {
      fail("has no end_header in its first 10000 lines");
    }
    const auto parts = words(line);
    const std::string where = "line " + std::to_string(number) + " '" + printable(trim(line)) + "'";
    if (parts.empty() || parts[0] == "comment" || parts[0] == "obj_info")
    {
      continue;
    }
    if (parts[0] == "format")
    {
      if (parts.size() < 2 ||
        (parts[1] != "ascii" && parts[1] != "binary_little_endian" &&
          parts[1] != "binary_big_endian"))
      {
        fail("has an unknown format, " + where);
      }
      format = parts[1] == "ascii"
        ? PlyFormat::Ascii
        : (parts[1] == "binary_little_endian" ? PlyFormat::BinaryLittle : PlyFormat::BinaryBig);
      hasFormat = true;
    }
    else if (parts[0] == "element")
    {
      long long count = 0;
      if (parts.size() != 3 || !parseInteger(parts[2], count) || count < 0)
      {
        fail("has a bad element declaration, " + where);
      }
      elements.push_back({ parts[1], static_cast<std::uint64_t>(count), {} });
    }
    else if (parts[0] == "property")
    {
      if (elements.empty())
      {
        fail("declares a property before any element, " + where);
      }
      PlyProperty property;
      if (parts.size() == 5 && parts[1] == "list" && plyBytes(parts[2]) && plyBytes(parts[3]) &&
        !plyIsFloat(parts[2]))
      {
        property = { parts[4], parts[3], true, parts[2] };
      }
      else if (parts.size() == 3 && plyBytes(parts[1]))
      {
        property = { parts[2], parts[1], false, {} };
      }
      else
      {
        fail("has a bad property declaration, " + where);
      }
      elements.back().properties.push_back(property);
    }
    else if (parts[0] == "end_header")
    {
      ended = true;
    }
    else
    {
      // Blender 2.4x's exporter writes "Created by Blender3D 247 - www.blender.org, source
      // file: ..." without 'comment'. Only element, property and format lines shape the body,
      // so such a line is read as a comment, with a warning (as VTK's PLY reader skips it).
      if (unknownLines++ == 0)
      {
        firstUnknown = where;
      }
    }
  }
  if (unknownLines > 0)
  {
    warn("the PLY file " + named(path) + " has " + std::to_string(unknownLines) +
      " header line(s) of no PLY keyword, read as comments: " + firstUnknown +
      (unknownLines > 1 ? " ..." : "") +
      " (start such a line with 'comment'; a misspelt element or property line would leave "
      "the body misread)");
  }
  if (!ended || !hasFormat)
  {
    fail(ended ? "has no format line" : "has a header without end_header");
  }

  // Every row holds at least one byte, so a count larger than the file is a lie; a row
  // without properties reads nothing, and a loop over 10^18 of them would never end.
  const std::uintmax_t fileBytes = fileSize(path);
  for (const auto& element : elements)
  {
    if (element.count > 0 && element.properties.empty())
    {
      fail("declares " + std::to_string(element.count) + " rows of the element '" +
        printable(element.name) +
        "' but no properties: give the element its properties or "
        "a count of 0");
    }
    if (element.count > fileBytes)
    {
      fail("declares " + std::to_string(element.count) + " rows of the element '" +
        printable(element.name) + "', more than the file's " + std::to_string(fileBytes) +
        " bytes can hold: the count is wrong or the file is truncated");
    }
  }

  const PlyElement* vertex = nullptr;
  const PlyElement* face = nullptr;
  // Scanned models (Stanford's igea, bunny2, the trimesh2 tools) store triangle strips
  // instead of faces: one list of indices, each -1 ending a strip.
  const PlyElement* strips = nullptr;
  for (const auto& element : elements)
  {
    vertex = element.name == "vertex" ? &element : vertex;
    face = element.name == "face" ? &element : face;
    strips = element.name == "tristrips" ? &element : strips;
  }
  if (!vertex || vertex->find("x") < 0 || vertex->find("y") < 0 || vertex->find("z") < 0)
  {
    fail("has no element 'vertex' with properties x, y and z");
  }
  checkOutputSize(path, "PLY", vertex->count, face ? face->count : 0, budget);
  auto indexListOf = [](const PlyElement* element)
  {
    if (!element)
    {
      return -1;
    }
    int index = element->find("vertex_indices");
    index = index < 0 ? element->find("vertex_index") : index;
    return index >= 0 && element->properties[static_cast<std::size_t>(index)].list ? index : -1;
  };
  const int indexProperty = indexListOf(face);
  const int stripIndexProperty = indexListOf(strips);
  const bool hasFaces = face && face->count > 0 && indexProperty >= 0;
  const bool hasStrips = strips && strips->count > 0 && stripIndexProperty >= 0;
  if (!hasFaces && !hasStrips)
  {
    fail("has no faces (an element 'face' or 'tristrips' with a list property vertex_indices): "
         "there is no surface to light");
  }
  if (!hasFaces)
  {
    face = nullptr;
  }
  if (!hasStrips)
  {
    strips = nullptr;
  }
  auto colourOf = [](const PlyElement& element, std::array<int, 3>& rgb)
  {
    for (const char* prefix : { "", "diffuse_" })
    {
      const std::string p = prefix;
      rgb = { { element.find(p + "red"), element.find(p + "green"), element.find(p + "blue") } };
      if (rgb[0] >= 0 && rgb[1] >= 0 && rgb[2] >= 0)
      {
        for (int i : rgb)
        {
          if (element.properties[static_cast<std::size_t>(i)].list)
          {
            return false;
          }
        }
        return true;
      }
    }
    return false;
  };
  std::array<int, 3> vertexRgb{}, faceRgb{}, stripRgb{};
  const bool vertexColours = colourOf(*vertex, vertexRgb);
  const bool faceColours = face && colourOf(*face, faceRgb);
  const bool stripColours = strips && colourOf(*strips, stripRgb);
  for (int axis : { vertex->find("x"), vertex->find("y"), vertex->find("z") })
  {
    if (vertex->properties[static_cast<std::size_t>(axis)].list)
    {
      fail("has a list property for a vertex coordinate");
    }
  }

  // The body: elements in header order; others are read and dropped.
  const std::uintmax_t size = fileBytes;
  PlyValues values(in, format, path);
  Scene scene;
  scene.format = "PLY";
  scene.points = vtkSmartPointer<vtkPoints>::New();
  scene.points->SetDataTypeToDouble();
  scene.polygons = vtkSmartPointer<vtkCellArray>::New();
  std::vector<std::array<double, 3>> vertexColour;
  std::vector<double> row;
  std::vector<vtkIdType> ids;
  std::uint64_t rowsRead = 0, valuesRead = 0;
  // Triangles the strips read so far can hold at most, for the memory check of each list.
  std::uint64_t stripTriangles = 0;
  std::size_t unlistedFaces = 0;
  bool verticesRead = false;
  auto pollProgress = [&]
  {
    poll(size > 0
        ? static_cast<double>(std::max<std::streamoff>(0, in.tellg())) / static_cast<double>(size)
        : 0.0);
  };
  // The cell's reflectance: the row's colour, else the mean of its vertices', else grey.
  auto addCell = [&](const vtkIdType* cell, vtkIdType count, const PlyElement& element,
                   bool rowColours, const std::array<int, 3>& rowRgb)
  {
    scene.polygons->InsertNextCell(count, cell);
    std::array<double, 3> rgb{ { FallbackReflectance, FallbackReflectance, FallbackReflectance } };
    if (rowColours)
    {
      for (std::size_t c = 0; c < 3; ++c)
      {
        const auto& property = element.properties[static_cast<std::size_t>(rowRgb[c])];
        rgb[c] = plyColour(row[static_cast<std::size_t>(rowRgb[c])], property.type);
      }
    }
    else if (vertexColours)
    {
      rgb = { { 0, 0, 0 } };
      for (vtkIdType i = 0; i < count; ++i)
      {
        for (std::size_t c = 0; c < 3; ++c)
        {
          rgb[c] += vertexColour[static_cast<std::size_t>(cell[i])][c] / static_cast<double>(count);
        }
      }
    }
    scene.cellReflectance.push_back(rgb);
  };
  for (const auto& element : elements)
  {
    const bool isVertex = &element == vertex, isFace = &element == face,
               isStrips = &element == strips;
    if ((isFace || isStrips) && !verticesRead)
    {
      fail("lists its " + std::string(isFace ? "faces" : "triangle strips") +
        " before its vertices: this reader needs the vertices first");
    }
    for (std::uint64_t e = 0; e < element.count; ++e)
    {
      if (++rowsRead % 65536 == 0)
      {
        pollProgress();
      }
      const std::string what = element.name + " " + std::to_string(e);
      row.assign(element.properties.size(), 0.0);
      for (std::size_t p = 0; p < element.properties.size(); ++p)
      {
        const auto& property = element.properties[p];
        if (!property.list)
        {
          row[p] = values.read(property.type, what + " " + property.name);
          continue;
        }
        const double count = values.read(property.countType, what + " " + property.name + " count");
        const bool stripIndices = isStrips && static_cast<int>(p) == stripIndexProperty;
        // A face has a few corners; a strip list may hold a whole model's strips, so its
        // bound is what the file can hold: a binary value's bytes, an ASCII digit and a space.
        const double most = stripIndices ? static_cast<double>(fileBytes) /
            (format == PlyFormat::Ascii ? 2.0 : static_cast<double>(plyBytes(property.type)))
                                         : 1e6;
        if (!(count >= 0) || count > most || count != std::floor(count))
        {
          std::ostringstream text;
          text << count;
          fail("has a list of " + text.str() + " values in " + what +
            (stripIndices ? ", more than the file's " + std::to_string(fileBytes) +
                  " bytes can hold: the count is wrong or the file is truncated"
                          : ""));
        }
        if (stripIndices)
        {
          // Each index after a strip's first two makes at most one triangle.
          stripTriangles += static_cast<std::uint64_t>(count);
          checkOutputSize(
            path, "PLY", vertex->count, (face ? face->count : 0) + stripTriangles, budget);
        }
        const bool indices = (isFace && static_cast<int>(p) == indexProperty) || stripIndices;
        // -1 ends a strip; written as an unsigned type, it is the type's largest value.
        const double restart = stripIndices && !plyIsSigned(property.type)
          ? std::ldexp(1.0, 8 * plyBytes(property.type)) - 1
          : -1;
        if (indices)
        {
          ids.clear();
        }
        for (std::uint64_t k = 0; k < static_cast<std::uint64_t>(count); ++k)
        {
          if (++valuesRead % 1048576 == 0)
          {
            pollProgress();
          }
          const double value = values.read(property.type, what + " " + property.name);
          if (!indices)
          {
            continue;
          }
          if (stripIndices && (value == -1 || value == restart))
          {
            ids.push_back(-1);
            continue;
          }
          if (value < 0 || value >= static_cast<double>(scene.points->GetNumberOfPoints()) ||
            value != std::floor(value))
          {
            std::ostringstream text;
            text << value;
            fail("names vertex " + text.str() + " in " + what + " but has " +
              std::to_string(scene.points->GetNumberOfPoints()) + " vertices" +
              (stripIndices ? " (-1 ends a strip)" : ""));
          }
          ids.push_back(static_cast<vtkIdType>(value));
        }
      }
      if (isVertex)
      {
        scene.points->InsertNextPoint(row[static_cast<std::size_t>(vertex->find("x"))],
          row[static_cast<std::size_t>(vertex->find("y"))],
          row[static_cast<std::size_t>(vertex->find("z"))]);
        if (vertexColours)
        {
          std::array<double, 3> rgb{};
          for (std::size_t c = 0; c < 3; ++c)
          {
            const auto& property = vertex->properties[static_cast<std::size_t>(vertexRgb[c])];
            rgb[c] = plyColour(row[static_cast<std::size_t>(vertexRgb[c])], property.type);
          }
          vertexColour.push_back(rgb);
        }
      }
      else if (isFace)
      {
        if (ids.size() < 3)
        {
          ++unlistedFaces;
          continue;
        }
        addCell(ids.data(), static_cast<vtkIdType>(ids.size()), *face, faceColours, faceRgb);
      }
      else if (isStrips)
      {
        // Triangle i of a strip is (v[i], v[i+1], v[i+2]), every other one turned
        // (v[i+1], v[i], v[i+2]) so that all face the same way. Strips join with
        // repeated indices: those triangles have no area and are dropped, but they count
        // for the turning, as for the tools that wrote them.
        std::size_t begin = 0;
        for (std::size_t i = 0; i <= ids.size(); ++i)
        {
          if (i < ids.size() && ids[i] >= 0)
          {
            continue;
          }
          for (std::size_t j = begin; j + 2 < i; ++j)
          {
            const bool turned = (j - begin) % 2 == 1;
            const vtkIdType triangle[3] = { ids[turned ? j + 1 : j], ids[turned ? j : j + 1],
              ids[j + 2] };
            if (triangle[0] != triangle[1] && triangle[1] != triangle[2] &&
              triangle[0] != triangle[2])
            {
              addCell(triangle, 3, *strips, stripColours, stripRgb);
            }
          }
          begin = i + 1;
        }
      }
    }
    verticesRead = verticesRead || isVertex;
  }
  if (scene.polygons->GetNumberOfCells() == 0)
  {
    fail(strips ? "has no faces with 3 or more vertices and no triangle in its strips: there is "
                  "no surface to light"
                : "has no faces with 3 or more vertices: there is no surface to light");
  }
  if (unlistedFaces > 0)
  {
    warn("the PLY file " + named(path) + " has " + std::to_string(unlistedFaces) +
      " faces with fewer than 3 vertices: they are skipped");
  }
  const std::string stem = std::filesystem::path(path).stem().string();
  if (((face && !faceColours) || (strips && !stripColours)) && !vertexColours)
  {
    warn(
      "the PLY file " + named(path) + " has no red/green/blue colours: every surface is grey 0.5");
  }
  // Colours of 255 (1.0) are common: clamp them with one warning for the file.
  std::size_t clamped = 0;
  for (auto& rgb : scene.cellReflectance)
  {
    for (double& value : rgb)
    {
      if (value < 0)
      {
        fail("has a negative colour: reflectance must be from 0 to 1");
      }
      if (value > 1.0 + 1e-9)
      {
        fail("has a colour above 1: give float colours from 0 to 1, 8-bit ones from 0 to 255 "
             "and 16-bit ones from 0 to 65535");
      }
      clamped += value > MaxReflectance ? 1 : 0;
      value = std::min(value, MaxReflectance);
    }
  }
  if (clamped > 0)
  {
    warn("the PLY file " + named(path) + " has " + std::to_string(clamped) +
      " colour components above 0.99 (255 in 8 bits): they are clamped to 0.99");
  }
  Material material;
  material.name = stem.empty() ? "ply" : stem;
  scene.materials.push_back(material);
  scene.materialOfCell.assign(static_cast<std::size_t>(scene.polygons->GetNumberOfCells()), 0);
  poll(1.0);
  return scene;
}

} // namespace mlr::scenefile
