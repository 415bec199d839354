// Wavefront OBJ and the MTL material libraries it names (readObj).
#include "RadiositySceneFormats.h"

#include "Plural.h"
#include "SceneText.h"
#include "SceneTextures.h"
#include "TextLines.h"

#include "vtkCellArray.h"
#include "vtkPoints.h"

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace mlr::scenefile
{

namespace
{
/// `text` before a '#' that may start a trailing comment, trimmed.
std::string beforeHash(const std::string& text)
{
  return trim(text.substr(0, text.find('#')));
}

/// The keyword of a line and the rest of it, without a trailing comment. A line that names a
/// material or a file keeps its '#': 3ds Max names materials "Material #25", and assimp and
/// others write such names as they are; only a line starting with '#' is a comment there.
void splitKeyword(const std::string& line, std::string& keyword, std::string& rest)
{
  static const std::set<std::string> naming = { "newmtl", "usemtl", "mtllib", "map_Kd", "map_Ke" };
  std::string text = trim(line);
  const auto space = text.find_first_of(" \t");
  keyword = text.substr(0, space);
  if (keyword.empty() || keyword[0] == '#' || naming.count(keyword) == 0)
  {
    const auto hash = text.find('#');
    if (hash != std::string::npos)
    {
      text.erase(hash);
    }
    text = trim(text);
    keyword = text.substr(0, text.find_first_of(" \t"));
  }
  const auto end = text.find_first_of(" \t");
  rest = end == std::string::npos ? std::string() : trim(text.substr(end));
}

/// FileError when `in` starts with a UTF-16 byte order mark (Windows tools save "Unicode"
/// text so): read byte by byte, its lines hold no keyword, and the file would seem empty.
void refuseUtf16(std::istream& in, const std::string& what)
{
  char bom[2] = { 0, 0 };
  in.read(bom, 2);
  const auto first = static_cast<unsigned char>(bom[0]),
             second = static_cast<unsigned char>(bom[1]);
  if (in.gcount() == 2 && ((first == 0xff && second == 0xfe) || (first == 0xfe && second == 0xff)))
  {
    throw FileError(what + " is UTF-16 text: save it as UTF-8 (or ASCII) and read it again");
  }
  in.clear();
  in.seekg(0);
}

struct MtlMaterial
{
  std::optional<std::array<double, 3>> kd, ke;
  std::string mapKd, mapKe; ///< texture files (map_Kd, map_Ke), empty when none
};

/// The file a texture map statement names ("map_Kd [options] file"): what follows the options
/// the MTL format defines, each with its number of values, so that a name with spaces stays
/// whole; the last word when an option is unknown. Back slashes become slashes; a relative
/// name is relative to the MTL file's folder. Empty when the statement names no file.
std::string mtlMapFile(const std::string& rest, const std::filesystem::path& folder)
{
  // Option -> how many values it takes; 0: one to three numbers (-o, -s, -t: u [v [w]]).
  static const std::map<std::string, int> options = { { "-blendu", 1 }, { "-blendv", 1 },
    { "-bm", 1 }, { "-boost", 1 }, { "-cc", 1 }, { "-clamp", 1 }, { "-imfchan", 1 }, { "-mm", 2 },
    { "-o", 0 }, { "-s", 0 }, { "-t", 0 }, { "-texres", 1 }, { "-type", 1 } };
  std::vector<std::pair<std::size_t, std::size_t>> spans; // each word's start and length
  for (std::size_t at = rest.find_first_not_of(" \t"); at != std::string::npos;)
  {
    const std::size_t end = std::min(rest.find_first_of(" \t", at), rest.size());
    spans.emplace_back(at, end - at);
    at = rest.find_first_not_of(" \t", end);
  }
  auto word = [&](std::size_t i) { return rest.substr(spans[i].first, spans[i].second); };
  std::size_t i = 0;
  // The last word is always the file (or part of it), never an option's value.
  while (i + 1 < spans.size() && word(i).size() > 1 && word(i)[0] == '-')
  {
    const auto option = options.find(word(i));
    if (option == options.end())
    {
      i = spans.size() - 1;
      break;
    }
    ++i;
    double number = 0;
    for (int taken = 0; i + 1 < spans.size() &&
         (option->second == 0 ? taken < 3 && parseNumber(word(i), number) : taken < option->second);
         ++taken)
    {
      ++i;
    }
  }
  if (i >= spans.size())
  {
    return {};
  }
  std::string name = trim(rest.substr(spans[i].first));
  std::replace(name.begin(), name.end(), '\\', '/');
  // A '#' is kept in the name; when no such file exists, it may start a comment.
  std::error_code error;
  if (name.find('#') != std::string::npos && !std::filesystem::exists(folder / name, error) &&
    !beforeHash(name).empty() && std::filesystem::exists(folder / beforeHash(name), error))
  {
    name = beforeHash(name);
  }
  return (folder / name).string();
}

/// "r [g b]" as MTL colour statements write it (g and b default to r).
bool parseMtlColour(const std::string& rest, std::array<double, 3>& rgb)
{
  const auto parts = words(rest);
  if (parts.empty() || parts.size() > 3 || parts.size() == 2)
  {
    return false;
  }
  for (std::size_t i = 0; i < parts.size(); ++i)
  {
    if (!parseNumber(parts[i], rgb[i]))
    {
      return false;
    }
  }
  if (parts.size() == 1)
  {
    rgb[1] = rgb[2] = rgb[0];
  }
  return true;
}

/// The materials of an MTL file by name; the first definition of a name wins.
std::map<std::string, MtlMaterial> readMtl(
  const std::string& path, const std::string& objPath, const Warn& warn)
{
  std::ifstream in = openFile(path, "material library");
  refuseUtf16(in, "the material library " + named(path) + " of the OBJ file " + named(objPath));
  std::map<std::string, MtlMaterial> materials;
  LogicalLines lines(in);
  std::string line, keyword, rest;
  MtlMaterial* current = nullptr;
  std::string currentName;
  std::set<std::string> repeated;
  std::vector<std::string> seeThrough;
  while (lines.next(line))
  {
    splitKeyword(line, keyword, rest);
    const std::string where = "the material library " + named(path) + " of the OBJ file " +
      named(objPath) + ", line " + std::to_string(lines.number());
    if (keyword == "newmtl")
    {
      // Blender writes 'newmtl' without a name for a material slot without one (and 'usemtl'
      // without a name for its faces): the unnamed material, kept under the empty name.
      const bool known = materials.count(rest) != 0;
      if (known && repeated.insert(rest).second)
      {
        warn(
          where + ": material " + named(rest) + " is defined again; its first definition is used");
      }
      current = known ? nullptr : &materials[rest];
      currentName = rest;
    }
    else if ((keyword == "d" || keyword == "Tr") && current)
    {
      // Glass, curtains and cut-outs: a radiosity surface is opaque. Tr 1 is left out, as
      // some exporters write it for an opaque material.
      const std::vector<std::string> values = words(rest);
      double value = 0;
      if (!values.empty() && parseNumber(values.back(), value) &&
        (keyword == "d" ? value < 1 : value > 0 && value < 1) &&
        std::find(seeThrough.begin(), seeThrough.end(), currentName) == seeThrough.end())
      {
        seeThrough.push_back(currentName);
      }
    }
    else if ((keyword == "map_Kd" || keyword == "map_Ke") && current)
    {
      const std::string file = mtlMapFile(rest, std::filesystem::path(path).parent_path());
      if (file.empty())
      {
        warn(where + ": '" + keyword + "' names no file; it is ignored");
        continue;
      }
      (keyword == "map_Kd" ? current->mapKd : current->mapKe) = file;
    }
    else if ((keyword == "Kd" || keyword == "Ke") && current)
    {
      std::array<double, 3> rgb{};
      if (!parseMtlColour(rest, rgb))
      {
        if (rest.rfind("spectral", 0) == 0 || rest.rfind("xyz", 0) == 0)
        {
          warn(where + ": '" + keyword + " " + printable(rest) +
            "' (spectral or CIE XYZ colours) is not supported; " +
            (keyword == "Kd" ? "the material is grey" : "the material does not emit"));
          continue;
        }
        throw FileError(where + ": '" + keyword + " " + printable(rest) +
          "' is not a colour (1 or 3 finite numbers)");
      }
      (keyword == "Kd" ? current->kd : current->ke) = rgb;
    }
  }
  if (in.bad())
  {
    throw FileError("the material library " + named(path) + " could not be read to its end");
  }
  if (!seeThrough.empty())
  {
    std::string list;
    for (std::size_t i = 0; i < std::min<std::size_t>(seeThrough.size(), 3); ++i)
    {
      list += (i > 0 ? ", " : "") + named(seeThrough[i]);
    }
    warn("the material library " + named(path) + " has " + countOf(seeThrough.size(), "material") +
      " that let light through (d below 1, or Tr): " + list +
      (seeThrough.size() > 3 ? " ..." : "") +
      "; they are read as opaque: they block all the light that reaches them");
  }
  return materials;
}

/// The material library files an mtllib line names: the whole rest of the line when that is a
/// file (names with spaces), else each word. Backslashes separate folders, as in map_Kd:
/// files written on Windows name "sub\room.mtl".
std::vector<std::string> mtllibFiles(std::string rest, const std::filesystem::path& folder)
{
  std::replace(rest.begin(), rest.end(), '\\', '/');
  std::error_code error;
  const auto whole = folder / rest;
  if (std::filesystem::is_regular_file(whole, error))
  {
    return { whole.string() };
  }
  // Not a file with a '#' in its name: the '#' starts a comment.
  rest = beforeHash(rest);
  if (!rest.empty() && std::filesystem::is_regular_file(folder / rest, error))
  {
    return { (folder / rest).string() };
  }
  std::vector<std::string> files;
  for (const auto& word : words(rest))
  {
    files.push_back((folder / word).string());
  }
  return files;
}
} // namespace

Scene readObj(
  const std::string& path, const Warn& warn, const Progress& progress, const MemoryBudget& budget)
{
  std::ifstream in = openFile(path, "OBJ file");
  refuseUtf16(in, "the OBJ file " + named(path));
  const std::uintmax_t size = std::max<std::uintmax_t>(1, fileSize(path));
  // OBJ declares no counts: its lines, about 16 bytes each in files written by modellers, are
  // the estimate, each taken as a vertex and a triangle.
  checkOutputSize(path, "OBJ", size / 16, size / 16, budget, true);
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  ProgressPoll poll(progress, 0.0, 0.9);

  std::vector<double> coordinates;
  // 'v x y z r g b' (MeshLab, ZBrush and scanners write the colour of each vertex so): its
  // colour, and whether it has one.
  std::vector<std::array<double, 3>> vertexColour;
  std::vector<char> vertexHasColour;
  std::vector<long long> faceVertices; // resolved, 0-based, checked at the end
  std::vector<std::size_t> faceStart, faceLine;
  std::vector<int> faceMaterial;
  std::vector<std::string> usedMaterials; // in order of first use
  std::map<std::string, int> materialIds;
  std::vector<std::pair<std::string, std::size_t>> libraries; // file, line of its mtllib
  // The material of the faces that follow, named by the last 'usemtl' and counted once a face
  // takes it: a 'usemtl' without faces (exporters write one per slot) is no material.
  int currentMaterial = -1;
  std::string currentMaterialName = "none";
  std::size_t skippedPoints = 0, skippedLines = 0;

  auto materialId = [&](const std::string& name)
  {
    const auto found = materialIds.find(name);
    if (found != materialIds.end())
    {
      return found->second;
    }
    usedMaterials.push_back(name);
    return materialIds[name] = static_cast<int>(usedMaterials.size() - 1);
  };

  LogicalLines lines(in);
  std::string line, keyword, rest;
  std::size_t unnamedMaterials = 0, firstUnnamedLine = 0;
  bool facesBeforeUsemtl = false, sawUsemtl = false;
  while (lines.next(line))
  {
    if (lines.number() % 65536 == 0)
    {
      poll(
        static_cast<double>(std::max<std::streamoff>(0, in.tellg())) / static_cast<double>(size));
    }
    splitKeyword(line, keyword, rest);
    auto where = [&]()
    { return "the OBJ file " + named(path) + ", line " + std::to_string(lines.number()); };
    if (keyword == "v")
    {
      const auto parts = words(rest);
      double xyz[3];
      if (parts.size() < 3 || !parseNumber(parts[0], xyz[0]) || !parseNumber(parts[1], xyz[1]) ||
        !parseNumber(parts[2], xyz[2]))
      {
        throw FileError(
          where() + ": 'v " + printable(rest) + "' is not a vertex (3 finite numbers x y z)");
      }
      coordinates.insert(coordinates.end(), xyz, xyz + 3);
      std::array<double, 3> rgb{ { 1, 1, 1 } };
      const bool coloured = parts.size() == 6;
      if (coloured)
      {
        for (std::size_t c = 0; c < 3; ++c)
        {
          if (!parseNumber(parts[3 + c], rgb[c]) || rgb[c] < 0 || rgb[c] > 1)
          {
            throw FileError(where() + ": 'v " + printable(rest) +
              "' has a colour r g b that is not 3 numbers from 0 to 1");
          }
        }
      }
      vertexColour.push_back(rgb);
      vertexHasColour.push_back(coloured ? 1 : 0);
    }
    else if (keyword == "f")
    {
      const auto references = words(rest);
      if (references.size() < 3)
      {
        throw FileError(where() + ": a face needs at least 3 vertices, 'f " + printable(rest) +
          "' has " + std::to_string(references.size()));
      }
      const long long defined = static_cast<long long>(coordinates.size() / 3);
      faceStart.push_back(faceVertices.size());
      faceLine.push_back(lines.number());
      for (const auto& reference : references)
      {
        // v, v/vt, v/vt/vn or v//vn: only the vertex matters here.
        const std::string vertex = reference.substr(0, reference.find('/'));
        long long index = 0;
        if (!parseInteger(vertex, index) || index == 0 ||
          std::count(reference.begin(), reference.end(), '/') > 2)
        {
          throw FileError(where() + ": '" + printable(reference) +
            "' is not a vertex reference (v, v/vt, v/vt/vn or v//vn, v a non-zero whole number)");
        }
        // Compared without negating: -LLONG_MIN does not exist.
        if (index < 0 && index < -defined)
        {
          throw FileError(where() + ": '" + printable(reference) + "' names vertex " +
            std::to_string(index) + " but only " + std::to_string(defined) +
            " vertices are defined before it");
        }
        faceVertices.push_back(index < 0 ? defined + index : index - 1);
      }
      if (currentMaterial < 0)
      {
        currentMaterial = materialId(currentMaterialName);
      }
      faceMaterial.push_back(currentMaterial);
    }
    else if (keyword == "usemtl")
    {
      // Some exporters (Rhino) write a bare 'usemtl' for "no material": the faces after it
      // get the default one, as faces before any 'usemtl' do.
      if (rest.empty() && unnamedMaterials++ == 0)
      {
        firstUnnamedLine = lines.number();
      }
      facesBeforeUsemtl = facesBeforeUsemtl || (!sawUsemtl && !faceStart.empty());
      sawUsemtl = true;
      currentMaterialName = rest.empty() ? "none" : rest;
      currentMaterial = -1;
    }
    else if (keyword == "mtllib")
    {
      if (rest.empty())
      {
        throw FileError(where() + ": 'mtllib' without a file name");
      }
      for (const auto& file : mtllibFiles(rest, folder))
      {
        libraries.emplace_back(file, lines.number());
      }
    }
    else if (keyword == "p")
    {
      ++skippedPoints;
    }
    else if (keyword == "l")
    {
      ++skippedLines;
    }
  }
  if (in.bad())
  {
    throw FileError("the OBJ file " + named(path) + " could not be read to its end");
  }
  if (faceStart.empty())
  {
    throw FileError(
      "the OBJ file " + named(path) + " has no faces ('f' lines): there is no surface to light");
  }
  const long long vertexCount = static_cast<long long>(coordinates.size() / 3);
  for (std::size_t f = 0; f < faceStart.size(); ++f)
  {
    const std::size_t end = f + 1 < faceStart.size() ? faceStart[f + 1] : faceVertices.size();
    for (std::size_t k = faceStart[f]; k < end; ++k)
    {
      if (faceVertices[k] >= vertexCount)
      {
        throw FileError("the OBJ file " + named(path) + ", line " + std::to_string(faceLine[f]) +
          ": a face names vertex " + std::to_string(faceVertices[k] + 1) +
          " but the file defines " + std::to_string(vertexCount) + " ('v' lines)");
      }
    }
  }
  if (skippedPoints + skippedLines > 0)
  {
    warn("the OBJ file " + named(path) + " has " + std::to_string(skippedPoints) +
      " point ('p') and " + std::to_string(skippedLines) +
      " line ('l') elements: they are skipped, only faces are surfaces");
  }

  // Materials: Kd and Ke from the libraries.
  std::map<std::string, MtlMaterial> library;
  bool allLibrariesRead = !libraries.empty();
  // A library named on many lines is read once: a file can repeat one mtllib line without end.
  std::set<std::string> librariesSeen;
  for (const auto& [file, lineNumber] : libraries)
  {
    if (!librariesSeen.insert(file).second)
    {
      continue;
    }
    std::error_code error;
    if (!std::filesystem::is_regular_file(file, error))
    {
      allLibrariesRead = false;
      warn("the material library " + named(file) + " named by the OBJ file " + named(path) +
        " (line " + std::to_string(lineNumber) +
        ") does not exist: its materials are grey 0.5 and do not emit");
      continue;
    }
    for (auto& [name, material] : readMtl(file, path, warn))
    {
      library.emplace(name, material);
    }
  }
  if (libraries.empty())
  {
    warn("the OBJ file " + named(path) +
      " names no material library ('mtllib' line): every surface is grey 0.5");
  }

  // A map multiplies its colour by the texture's mean (each file decoded once); a texture that
  // cannot be used is a warning and the colour alone stays.
  std::map<std::string, std::pair<std::optional<std::array<double, 3>>, std::string>> textureMeans;
  auto applyMap = [&](const std::string& file, const char* keyword, const std::string& what,
                    std::optional<std::array<double, 3>>& colour)
  {
    auto found = textureMeans.find(file);
    if (found == textureMeans.end())
    {
      std::string bytes, problem;
      std::optional<std::array<double, 3>> mean;
      if (readTextureFile(file, bytes, problem))
      {
        mean = imageMean(bytes, problem);
      }
      found = textureMeans.emplace(file, std::make_pair(mean, problem)).first;
    }
    const auto& [mean, problem] = found->second;
    if (!mean)
    {
      warn("the " + what + ": its " + keyword + " texture " + named(file) + ": " + problem +
        ", so " + (keyword[5] == 'd' ? "Kd" : "Ke") + " alone is used");
      return;
    }
    std::array<double, 3> product = colour.value_or(std::array<double, 3>{ { 1, 1, 1 } });
    for (std::size_t c = 0; c < 3; ++c)
    {
      product[c] *= (*mean)[c];
    }
    colour = product;
  };

  // A bare 'usemtl' takes the libraries' unnamed material (Blender's 'newmtl' without a name)
  // when they have one and no face before any 'usemtl' shares its default material.
  const bool unnamedFromLibrary =
    unnamedMaterials > 0 && !facesBeforeUsemtl && library.count(std::string()) != 0;
  if (unnamedMaterials > 0)
  {
    warn("the OBJ file " + named(path) + ", line " + std::to_string(firstUnnamedLine) +
      ": 'usemtl' without a material name; the faces after it (and after any other such line) " +
      (unnamedFromLibrary
          ? "have the material library's unnamed material ('newmtl' without a name), 'none' here"
          : "have the default material, grey 0.5"));
  }

  Scene scene;
  scene.format = "OBJ";
  // Each material's Kd before it is clamped (1 without one), which vertex colours multiply.
  std::vector<std::array<double, 3>> unclampedKd;
  for (const auto& name : usedMaterials)
  {
    unclampedKd.push_back({ { 1, 1, 1 } });
    Material material;
    material.name = name;
    auto found = library.find(name == "none" && unnamedFromLibrary ? std::string() : name);
    // A '#' kept in a name may have started a trailing comment ("usemtl wood # oak", or
    // "newmtl wood # oak"): the names match before it when they do not as they are.
    if (found == library.end() && !beforeHash(name).empty())
    {
      const std::string cut = beforeHash(name);
      auto match = library.find(cut);
      if (match == library.end())
      {
        std::size_t matches = 0;
        for (auto candidate = library.begin(); candidate != library.end(); ++candidate)
        {
          if (beforeHash(candidate->first) == cut && matches++ == 0)
          {
            match = candidate;
          }
        }
        match = matches == 1 ? match : library.end();
      }
      if (match != library.end())
      {
        warn("the material " + named(name) + " of " + named(path) +
          " is not defined in its material libraries; " + named(match->first) +
          " is used, the text after '#' taken as a comment");
        found = match;
      }
    }
    const std::string what = "material " + named(name) + " of " + named(path);
    if (found != library.end())
    {
      // map_Kd without Kd: the texture alone is the colour (Kd 1), as viewers show it.
      std::optional<std::array<double, 3>> kd = found->second.kd;
      if (!found->second.mapKd.empty())
      {
        applyMap(found->second.mapKd, "map_Kd", what, kd);
      }
      if (kd)
      {
        unclampedKd.back() = *kd;
        material.reflectance = checkedReflectance(*kd, "the " + what, warn);
      }
      else
      {
        warn("the " + what + " has no Kd: it is grey 0.5");
      }
      if (found->second.ke)
      {
        material.radiance = *found->second.ke;
        for (double value : material.radiance)
        {
          if (value < 0)
          {
            throw FileError("the " + what + " has a negative Ke: emission must be 0 or more");
          }
        }
        // map_Ke scales an emission Ke gives (as glTF's emissive texture its factor): without
        // Ke, or with Ke 0, the material does not emit and the texture is not read.
        if (!found->second.mapKe.empty() &&
          material.radiance != std::array<double, 3>{ { 0, 0, 0 } })
        {
          std::optional<std::array<double, 3>> ke = material.radiance;
          applyMap(found->second.mapKe, "map_Ke", what, ke);
          material.radiance = *ke;
        }
      }
    }
    else if (allLibrariesRead && name != "none")
    {
      warn("the " + what + " is not defined in its material libraries: it is grey 0.5");
    }
    else if (name == "none" && !libraries.empty() && unnamedMaterials == 0)
    {
      warn("the OBJ file " + named(path) +
        " has faces before any 'usemtl': their material 'none' is grey 0.5");
    }
    scene.materials.push_back(material);
  }

  scene.points = vtkSmartPointer<vtkPoints>::New();
  scene.points->SetDataTypeToDouble();
  scene.points->SetNumberOfPoints(vertexCount);
  for (long long i = 0; i < vertexCount; ++i)
  {
    scene.points->SetPoint(i, &coordinates[3 * i]);
  }
  scene.polygons = vtkSmartPointer<vtkCellArray>::New();
  scene.polygons->AllocateExact(
    static_cast<vtkIdType>(faceStart.size()), static_cast<vtkIdType>(faceVertices.size()));
  std::vector<vtkIdType> ids;
  for (std::size_t f = 0; f < faceStart.size(); ++f)
  {
    const std::size_t end = f + 1 < faceStart.size() ? faceStart[f + 1] : faceVertices.size();
    ids.assign(faceVertices.begin() + static_cast<std::ptrdiff_t>(faceStart[f]),
      faceVertices.begin() + static_cast<std::ptrdiff_t>(end));
    scene.polygons->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
  }
  scene.materialOfCell = std::move(faceMaterial);
  // A face whose vertices all have a colour: their mean times its material's Kd (as glTF's
  // COLOR_0 times its factor), clamped once; the other faces keep their material's.
  if (std::find(vertexHasColour.begin(), vertexHasColour.end(), 1) != vertexHasColour.end())
  {
    std::size_t clamped = 0;
    scene.cellReflectance.resize(faceStart.size());
    for (std::size_t f = 0; f < faceStart.size(); ++f)
    {
      const auto material = static_cast<std::size_t>(scene.materialOfCell[f]);
      const std::size_t end = f + 1 < faceStart.size() ? faceStart[f + 1] : faceVertices.size();
      std::array<double, 3> mean{ { 0, 0, 0 } };
      bool coloured = true;
      for (std::size_t k = faceStart[f]; k < end && coloured; ++k)
      {
        const auto v = static_cast<std::size_t>(faceVertices[k]);
        coloured = vertexHasColour[v] != 0;
        for (std::size_t c = 0; c < 3; ++c)
        {
          mean[c] += vertexColour[v][c] / static_cast<double>(end - faceStart[f]);
        }
      }
      if (!coloured)
      {
        scene.cellReflectance[f] = scene.materials[material].reflectance;
        continue;
      }
      for (std::size_t c = 0; c < 3; ++c)
      {
        const double value = unclampedKd[material][c] * mean[c];
        clamped += value > MaxReflectance ? 1 : 0;
        scene.cellReflectance[f][c] = std::min(value, MaxReflectance);
      }
    }
    if (clamped > 0)
    {
      warn("the OBJ file " + named(path) + ": " + std::to_string(clamped) +
        " reflectance components of faces coloured by their vertices are clamped to 0.99");
    }
  }
  poll(1.0);
  return scene;
}

} // namespace mlr::scenefile
