#include "RadiositySceneFormats.h"

#include "vtkCellArray.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkJPEGReader.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"

#include "vtk_nlohmannjson.h"
#include "vtk_png.h"
#include VTK_NLOHMANN_JSON(json.hpp)

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>

namespace mlr::scenefile
{

namespace
{
using Json = nlohmann::json;

std::string named(const std::string& text)
{
  return "'" + text + "'";
}

/// A piece of a file as messages show it: at most 60 characters, control bytes as '?'.
std::string printable(const std::string& text)
{
  std::string shown = text.substr(0, 60);
  for (char& c : shown)
  {
    c = static_cast<unsigned char>(c) < 0x20 || c == 0x7f ? '?' : c;
  }
  return text.size() > 60 ? shown + "..." : shown;
}

std::string trim(const std::string& text)
{
  const auto first = text.find_first_not_of(" \t\r\n\f\v");
  if (first == std::string::npos)
  {
    return {};
  }
  return text.substr(first, text.find_last_not_of(" \t\r\n\f\v") - first + 1);
}

std::vector<std::string> words(const std::string& text)
{
  std::vector<std::string> result;
  std::istringstream in(text);
  std::string word;
  while (in >> word)
  {
    result.push_back(word);
  }
  return result;
}

/// A whole word as a finite number (locale independent, as files are written).
bool parseNumber(const std::string& word, double& value)
{
  const char* first = word.data();
  const char* last = word.data() + word.size();
  if (first != last && *first == '+')
  {
    ++first;
  }
  const auto [end, error] = std::from_chars(first, last, value);
  return error == std::errc() && end == last && std::isfinite(value);
}

bool parseInteger(const std::string& word, long long& value)
{
  const char* first = word.data();
  const char* last = word.data() + word.size();
  if (first != last && *first == '+')
  {
    ++first;
  }
  const auto [end, error] = std::from_chars(first, last, value);
  return error == std::errc() && end == last;
}

std::uintmax_t fileSize(const std::string& path)
{
  std::error_code error;
  const auto size = std::filesystem::file_size(path, error);
  return error ? 0 : size;
}

/// Opens `path` for reading or throws FileError naming `kind` ("OBJ file") and the reason.
std::ifstream openFile(const std::string& path, const std::string& kind)
{
  std::error_code error;
  if (!std::filesystem::exists(path, error))
  {
    throw FileError("the " + kind + " " + named(path) + " does not exist");
  }
  if (std::filesystem::is_directory(path, error))
  {
    throw FileError("the " + kind + " " + named(path) + " is a folder, not a file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in)
  {
    throw FileError("the " + kind + " " + named(path) + " cannot be opened: " + std::strerror(errno));
  }
  return in;
}

/// The logical lines of an OBJ or MTL file: a line ending in a backslash continues on the next.
class LogicalLines
{
public:
  explicit LogicalLines(std::istream& in)
    : In(in)
  {
  }

  bool next(std::string& line)
  {
    line.clear();
    std::string part;
    bool any = false;
    while (std::getline(this->In, part))
    {
      any = true;
      ++this->Number;
      if (!part.empty() && part.back() == '\r')
      {
        part.pop_back();
      }
      if (!part.empty() && part.back() == '\\')
      {
        part.back() = ' ';
        line += part;
        continue;
      }
      line += part;
      return true;
    }
    return any;
  }

  std::size_t number() const { return this->Number; }
  std::uintmax_t position() { return static_cast<std::uintmax_t>(std::max<std::streamoff>(0, this->In.tellg())); }

private:
  std::istream& In;
  std::size_t Number = 0;
};

/// The keyword of a line and the rest of it, without a trailing comment.
void splitKeyword(const std::string& line, std::string& keyword, std::string& rest)
{
  std::string text = line;
  const auto hash = text.find('#');
  if (hash != std::string::npos)
  {
    text.erase(hash);
  }
  text = trim(text);
  const auto space = text.find_first_of(" \t");
  keyword = text.substr(0, space);
  rest = space == std::string::npos ? std::string() : trim(text.substr(space));
}

/// Reads the progress callback every so many units of work, and stops on request.
class ProgressPoll
{
public:
  ProgressPoll(const Progress& progress, double from, double to)
    : Callback(progress)
    , From(from)
    , To(to)
  {
  }
  void operator()(double fraction)
  {
    if (this->Callback && !this->Callback(this->From + (this->To - this->From) * std::clamp(fraction, 0.0, 1.0)))
    {
      throw Aborted{};
    }
  }

private:
  const Progress& Callback;
  double From, To;
};

// =========================================================================================
// Textures: the mean colour of an image (glTF base colour and emissive textures, MTL map_Kd
// and map_Ke), which multiplies the material's colour
// =========================================================================================

/// A texture's mean needs no more than this many texels: larger images are refused rather than
/// risking memory on a damaged header.
constexpr std::uint64_t MaxTexturePixels = std::uint64_t(1) << 26;
/// The largest texture file read (MTL maps): a 64-Mpixel PNG seldom needs more, and a bigger
/// file is refused before any of it is read.
constexpr std::uintmax_t MaxTextureFileBytes = std::uintmax_t(256) << 20;
/// A glTF's external buffer or image file larger than this is refused before it is read:
/// every byte is held in memory.
constexpr std::uintmax_t MaxResourceFileBytes = std::uintmax_t(4) << 30;

bool isPng(const std::string& bytes)
{
  return bytes.size() >= 8 && bytes.compare(1, 3, "PNG") == 0;
}

bool isJpeg(const std::string& bytes)
{
  return bytes.size() >= 3 && static_cast<unsigned char>(bytes[0]) == 0xff &&
    static_cast<unsigned char>(bytes[1]) == 0xd8;
}

double srgbToLinear(double value)
{
  return value <= 0.04045 ? value / 12.92 : std::pow((value + 0.055) / 1.055, 2.4);
}

/// Records what VTK's image readers report, so that a texture they cannot decode becomes one
/// warning naming the material instead of errors without context.
class ReaderMessages : public vtkCommand
{
public:
  static ReaderMessages* New() { return new ReaderMessages; }
  void Execute(vtkObject*, unsigned long event, void* data) override
  {
    std::string text = data ? static_cast<const char*>(data) : "";
    // vtkOutputWindow-style text: "ERROR: In file, line N\nvtkClass (0x...): message"
    const auto close = text.find("): ");
    if (close != std::string::npos)
    {
      text = text.substr(close + 3);
    }
    if (event == vtkCommand::ErrorEvent)
    {
      this->Errors.push_back(trim(text));
    }
  }
  std::vector<std::string> Errors;
};

/// A PNG file's texels as 8-bit sRGB RGBA, through libpng's simplified API, which reports a
/// damaged file as an error (VTK 9.2's vtkPNGReader crashes on some damaged data).
vtkSmartPointer<vtkImageData> decodePng(const std::string& bytes, std::string& problem)
{
  png_image png;
  std::memset(&png, 0, sizeof(png));
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&png, bytes.data(), bytes.size()))
  {
    problem = std::string("its PNG image could not be decoded (") + png.message + ")";
    png_image_free(&png);
    return nullptr;
  }
  if (static_cast<std::uint64_t>(png.width) * png.height > MaxTexturePixels)
  {
    problem = "its PNG image is larger than 64 Mpixels";
    png_image_free(&png);
    return nullptr;
  }
  png.format = PNG_FORMAT_RGBA;
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(static_cast<int>(png.width), static_cast<int>(png.height), 1);
  image->AllocateScalars(VTK_UNSIGNED_CHAR, 4);
  if (!png_image_finish_read(&png, nullptr, image->GetScalarPointer(), 0, nullptr))
  {
    problem = std::string("its PNG image could not be decoded (") + png.message + ")";
    png_image_free(&png);
    return nullptr;
  }
  return image;
}

/// The width x height of a JPEG's frame header (SOFn), read before vtkJPEGReader allocates the
/// image it declares; 0 when no frame header is found (the reader then reports the damage).
std::uint64_t jpegPixels(const std::string& bytes)
{
  auto byte = [&](std::size_t i) { return static_cast<std::uint64_t>(static_cast<unsigned char>(bytes[i])); };
  std::size_t at = 2;
  while (at + 4 <= bytes.size() && byte(at) == 0xff)
  {
    const std::uint64_t marker = byte(at + 1);
    if (marker == 0xff)
    {
      ++at; // fill byte
      continue;
    }
    if (marker == 0x01 || (marker >= 0xd0 && marker <= 0xd8))
    {
      at += 2; // markers without a length
      continue;
    }
    if (marker == 0xd9 || marker == 0xda)
    {
      return 0; // end of image or scan data before any frame header
    }
    const bool frame = marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
    if (frame)
    {
      return at + 9 <= bytes.size() ? ((byte(at + 5) << 8) | byte(at + 6)) * ((byte(at + 7) << 8) | byte(at + 8)) : 0;
    }
    at += 2 + static_cast<std::size_t>((byte(at + 2) << 8) | byte(at + 3));
  }
  return 0;
}

/// The mean linear colour of an encoded PNG or JPEG image (sRGB, as colour textures are); no
/// value, and `problem` saying why ("its image is ..."), when it cannot be decoded.
std::optional<std::array<double, 3>> imageMean(const std::string& bytes, std::string& problem)
{
  vtkSmartPointer<vtkImageData> image;
  if (isPng(bytes))
  {
    image = decodePng(bytes, problem);
  }
  else if (isJpeg(bytes))
  {
    if (jpegPixels(bytes) > MaxTexturePixels)
    {
      problem = "its JPEG image is larger than 64 Mpixels";
      return std::nullopt;
    }
    vtkNew<vtkJPEGReader> reader;
    vtkNew<ReaderMessages> messages;
    reader->AddObserver(vtkCommand::ErrorEvent, messages);
    reader->AddObserver(vtkCommand::WarningEvent, messages);
    reader->SetMemoryBuffer(bytes.data());
    reader->SetMemoryBufferLength(static_cast<vtkIdType>(bytes.size()));
    reader->Update();
    image = reader->GetOutput();
    if (!messages->Errors.empty())
    {
      problem = "its image could not be decoded (" + messages->Errors.front() + ")";
      image = nullptr;
    }
  }
  else
  {
    problem = "its image is neither PNG nor JPEG";
  }
  vtkDataArray* texels = image ? image->GetPointData()->GetScalars() : nullptr;
  if (problem.empty() && (!texels || texels->GetNumberOfTuples() == 0))
  {
    problem = "its image is empty";
  }
  if (!problem.empty())
  {
    return std::nullopt;
  }
  const int components = texels->GetNumberOfComponents();
  const double scale = texels->GetDataTypeMax() > 1 ? texels->GetDataTypeMax() : 1.0;
  std::array<double, 256> table{};
  for (std::size_t i = 0; i < 256; ++i)
  {
    table[i] = srgbToLinear(static_cast<double>(i) / 255.0);
  }
  const bool eightBit = scale == 255.0;
  std::array<double, 3> sum{ { 0, 0, 0 } };
  const vtkIdType count = texels->GetNumberOfTuples();
  for (vtkIdType t = 0; t < count; ++t)
  {
    for (int c = 0; c < 3; ++c)
    {
      // Grey (and grey + alpha) images hold one colour component.
      const double raw = texels->GetComponent(t, components >= 3 ? c : 0);
      sum[static_cast<std::size_t>(c)] += eightBit
        ? table[static_cast<std::size_t>(std::clamp(raw, 0.0, 255.0))]
        : srgbToLinear(std::clamp(raw / scale, 0.0, 1.0));
    }
  }
  for (double& s : sum)
  {
    s /= static_cast<double>(count);
  }
  return sum;
}

/// The bytes of a texture file an MTL map names, or false with `problem` ("its file ..."):
/// only a regular file of at most MaxTextureFileBytes is read, and only when its first bytes
/// are a PNG or JPEG signature, so that a folder, a device (/dev/zero), a FIFO or a large file
/// of another kind is refused at once.
bool readTextureFile(const std::filesystem::path& file, std::string& bytes, std::string& problem)
{
  std::error_code error;
  const auto status = std::filesystem::status(file, error);
  if (!std::filesystem::exists(status))
  {
    problem = "its file does not exist";
    return false;
  }
  if (!std::filesystem::is_regular_file(status))
  {
    problem = std::filesystem::is_directory(status) ? "its file is a folder" : "its file is not a regular file";
    return false;
  }
  const std::uintmax_t size = std::filesystem::file_size(file, error);
  if (error || size > MaxTextureFileBytes)
  {
    problem = error ? "its file's size cannot be read" : "its file is larger than 256 MiB";
    return false;
  }
  std::ifstream in(file, std::ios::binary);
  if (!in)
  {
    problem = std::string("its file cannot be opened: ") + std::strerror(errno);
    return false;
  }
  bytes.assign(std::min<std::uintmax_t>(size, 8), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!isPng(bytes) && !isJpeg(bytes))
  {
    problem = "its image is neither PNG nor JPEG";
    return false;
  }
  const std::size_t start = bytes.size();
  bytes.resize(static_cast<std::size_t>(size));
  in.read(bytes.data() + start, static_cast<std::streamsize>(bytes.size() - start));
  bytes.resize(start + static_cast<std::size_t>(in.gcount())); // a file that shrank meanwhile
  if (in.bad())
  {
    problem = "its file could not be read";
    return false;
  }
  return true;
}

// =========================================================================================
// OBJ + MTL
// =========================================================================================

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
  static const std::map<std::string, int> options = { { "-blendu", 1 }, { "-blendv", 1 }, { "-bm", 1 },
    { "-boost", 1 }, { "-cc", 1 }, { "-clamp", 1 }, { "-imfchan", 1 }, { "-mm", 2 }, { "-o", 0 },
    { "-s", 0 }, { "-t", 0 }, { "-texres", 1 }, { "-type", 1 } };
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
    for (int taken = 0; i + 1 < spans.size() && (option->second == 0 ? taken < 3 && parseNumber(word(i), number)
                                                                      : taken < option->second);
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
std::map<std::string, MtlMaterial> readMtl(const std::string& path, const std::string& objPath, const Warn& warn)
{
  std::ifstream in = openFile(path, "material library");
  std::map<std::string, MtlMaterial> materials;
  LogicalLines lines(in);
  std::string line, keyword, rest;
  MtlMaterial* current = nullptr;
  std::set<std::string> repeated;
  while (lines.next(line))
  {
    splitKeyword(line, keyword, rest);
    const std::string where = "the material library " + named(path) + " of the OBJ file " + named(objPath) +
      ", line " + std::to_string(lines.number());
    if (keyword == "newmtl")
    {
      if (rest.empty())
      {
        throw FileError(where + ": 'newmtl' without a material name");
      }
      const bool known = materials.count(rest) != 0;
      if (known && repeated.insert(rest).second)
      {
        warn(where + ": material " + named(rest) + " is defined again; its first definition is used");
      }
      current = known ? nullptr : &materials[rest];
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
          warn(where + ": '" + keyword + " " + printable(rest) + "' (spectral or CIE XYZ colours) is not supported; " +
            (keyword == "Kd" ? "the material is grey" : "the material does not emit"));
          continue;
        }
        throw FileError(where + ": '" + keyword + " " + printable(rest) + "' is not a colour (1 or 3 finite numbers)");
      }
      (keyword == "Kd" ? current->kd : current->ke) = rgb;
    }
  }
  if (in.bad())
  {
    throw FileError("the material library " + named(path) + " could not be read to its end");
  }
  return materials;
}

/// The material library files an mtllib line names: the whole rest of the line when that is a
/// file (names with spaces), else each word.
std::vector<std::string> mtllibFiles(const std::string& rest, const std::filesystem::path& folder)
{
  std::error_code error;
  const auto whole = folder / rest;
  if (std::filesystem::is_regular_file(whole, error))
  {
    return { whole.string() };
  }
  std::vector<std::string> files;
  for (const auto& word : words(rest))
  {
    files.push_back((folder / word).string());
  }
  return files;
}
} // namespace

std::array<double, 3> checkedReflectance(
  std::array<double, 3> rgb, const std::string& what, const Warn& warn)
{
  bool clamped = false;
  for (double& value : rgb)
  {
    if (!std::isfinite(value) || value < 0)
    {
      std::ostringstream s;
      s << what << " has the reflectance (" << rgb[0] << ", " << rgb[1] << ", " << rgb[2]
        << "): each component must be a number from 0 to 1";
      throw FileError(s.str());
    }
    if (value > MaxReflectance)
    {
      clamped = true;
    }
  }
  if (clamped)
  {
    std::ostringstream s;
    s << what << " has the reflectance (" << rgb[0] << ", " << rgb[1] << ", " << rgb[2]
      << "): components above " << MaxReflectance << " are clamped to " << MaxReflectance
      << " (a surface reflecting all the light it receives has no finite radiosity)";
    warn(s.str());
    for (double& value : rgb)
    {
      value = std::min(value, MaxReflectance);
    }
  }
  return rgb;
}

Scene readObj(const std::string& path, const Warn& warn, const Progress& progress)
{
  std::ifstream in = openFile(path, "OBJ file");
  const std::uintmax_t size = std::max<std::uintmax_t>(1, fileSize(path));
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  ProgressPoll poll(progress, 0.0, 0.9);

  std::vector<double> coordinates;
  std::vector<long long> faceVertices;      // resolved, 0-based, checked at the end
  std::vector<std::size_t> faceStart, faceLine;
  std::vector<int> faceMaterial;
  std::vector<std::string> usedMaterials;   // in order of first use
  std::map<std::string, int> materialIds;
  std::vector<std::pair<std::string, std::size_t>> libraries; // file, line of its mtllib
  int currentMaterial = -1;
  std::size_t skippedPoints = 0, skippedLines = 0;

  auto materialId = [&](const std::string& name) {
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
  while (lines.next(line))
  {
    if (lines.number() % 65536 == 0)
    {
      poll(static_cast<double>(lines.position()) / static_cast<double>(size));
    }
    splitKeyword(line, keyword, rest);
    auto where = [&]() { return "the OBJ file " + named(path) + ", line " + std::to_string(lines.number()); };
    if (keyword == "v")
    {
      const auto parts = words(rest);
      double xyz[3];
      if (parts.size() < 3 || !parseNumber(parts[0], xyz[0]) || !parseNumber(parts[1], xyz[1]) ||
        !parseNumber(parts[2], xyz[2]))
      {
        throw FileError(where() + ": 'v " + printable(rest) + "' is not a vertex (3 finite numbers x y z)");
      }
      coordinates.insert(coordinates.end(), xyz, xyz + 3);
    }
    else if (keyword == "f")
    {
      const auto references = words(rest);
      if (references.size() < 3)
      {
        throw FileError(where() + ": a face needs at least 3 vertices, 'f " + printable(rest) + "' has " +
          std::to_string(references.size()));
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
        if (index < 0 && -index > defined)
        {
          throw FileError(where() + ": '" + printable(reference) + "' names vertex " + std::to_string(index) +
            " but only " + std::to_string(defined) + " vertices are defined before it");
        }
        faceVertices.push_back(index < 0 ? defined + index : index - 1);
      }
      if (currentMaterial < 0)
      {
        currentMaterial = materialId("none");
      }
      faceMaterial.push_back(currentMaterial);
    }
    else if (keyword == "usemtl")
    {
      if (rest.empty())
      {
        throw FileError(where() + ": 'usemtl' without a material name");
      }
      currentMaterial = materialId(rest);
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
    throw FileError("the OBJ file " + named(path) + " has no faces ('f' lines): there is no surface to light");
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
          ": a face names vertex " + std::to_string(faceVertices[k] + 1) + " but the file defines " +
          std::to_string(vertexCount) + " ('v' lines)");
      }
    }
  }
  if (skippedPoints + skippedLines > 0)
  {
    warn("the OBJ file " + named(path) + " has " + std::to_string(skippedPoints) + " point ('p') and " +
      std::to_string(skippedLines) + " line ('l') elements: they are skipped, only faces are surfaces");
  }

  // Materials: Kd and Ke from the libraries.
  std::map<std::string, MtlMaterial> library;
  bool allLibrariesRead = !libraries.empty();
  for (const auto& [file, lineNumber] : libraries)
  {
    std::error_code error;
    if (!std::filesystem::is_regular_file(file, error))
    {
      allLibrariesRead = false;
      warn("the material library " + named(file) + " named by the OBJ file " + named(path) + " (line " +
        std::to_string(lineNumber) + ") does not exist: its materials are grey 0.5 and do not emit");
      continue;
    }
    for (auto& [name, material] : readMtl(file, path, warn))
    {
      library.emplace(name, material);
    }
  }
  if (libraries.empty())
  {
    warn("the OBJ file " + named(path) + " names no material library ('mtllib' line): every surface is grey 0.5");
  }

  // A map multiplies its colour by the texture's mean (each file decoded once); a texture that
  // cannot be used is a warning and the colour alone stays.
  std::map<std::string, std::pair<std::optional<std::array<double, 3>>, std::string>> textureMeans;
  auto applyMap = [&](const std::string& file, const char* keyword, const std::string& what,
                    std::optional<std::array<double, 3>>& colour) {
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
      warn("the " + what + ": its " + keyword + " texture " + named(file) + ": " + problem + ", so " +
        (keyword[5] == 'd' ? "Kd" : "Ke") + " alone is used");
      return;
    }
    std::array<double, 3> product = colour.value_or(std::array<double, 3>{ { 1, 1, 1 } });
    for (std::size_t c = 0; c < 3; ++c)
    {
      product[c] *= (*mean)[c];
    }
    colour = product;
  };

  Scene scene;
  scene.format = "OBJ";
  for (const auto& name : usedMaterials)
  {
    Material material;
    material.name = name;
    const auto found = library.find(name);
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
        if (!found->second.mapKe.empty() && material.radiance != std::array<double, 3>{ { 0, 0, 0 } })
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
    else if (name == "none" && !libraries.empty())
    {
      warn("the OBJ file " + named(path) + " has faces before any 'usemtl': their material 'none' is grey 0.5");
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
  scene.polygons->AllocateExact(static_cast<vtkIdType>(faceStart.size()), static_cast<vtkIdType>(faceVertices.size()));
  std::vector<vtkIdType> ids;
  for (std::size_t f = 0; f < faceStart.size(); ++f)
  {
    const std::size_t end = f + 1 < faceStart.size() ? faceStart[f + 1] : faceVertices.size();
    ids.assign(faceVertices.begin() + static_cast<std::ptrdiff_t>(faceStart[f]),
      faceVertices.begin() + static_cast<std::ptrdiff_t>(end));
    scene.polygons->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
  }
  scene.materialOfCell = std::move(faceMaterial);
  poll(1.0);
  return scene;
}

// =========================================================================================
// glTF 2.0
// =========================================================================================

namespace
{
std::int64_t componentBytes(std::int64_t componentType)
{
  switch (componentType)
  {
    case 5120:
    case 5121:
      return 1;
    case 5122:
    case 5123:
      return 2;
    case 5125:
    case 5126:
      return 4;
    default:
      return 0;
  }
}

std::int64_t typeComponents(const std::string& type)
{
  static const std::map<std::string, std::int64_t> components = { { "SCALAR", 1 }, { "VEC2", 2 },
    { "VEC3", 3 }, { "VEC4", 4 }, { "MAT2", 4 }, { "MAT3", 9 }, { "MAT4", 16 } };
  const auto found = components.find(type);
  return found == components.end() ? 0 : found->second;
}

/// Checks of the JSON that keep the reading below inside its arrays and buffers: every index
/// names an entry the file has, every accessor fits in its buffer view and buffer, the node
/// hierarchy is a forest.
class GltfChecks
{
public:
  GltfChecks(const Json& root, const std::string& path)
    : Root(root)
    , Path(path)
  {
  }

  [[noreturn]] void fail(const std::string& problem) const
  {
    throw FileError("the glTF file " + named(this->Path) + ": " + problem);
  }

  const Json& array(const char* name) const
  {
    static const Json empty = Json::array();
    const auto found = this->Root.find(name);
    if (found == this->Root.end())
    {
      return empty;
    }
    if (!found->is_array())
    {
      this->fail(std::string("'") + name + "' is not an array");
    }
    return *found;
  }

  /// An optional integer member; `fallback` when absent.
  std::int64_t integer(const Json& object, const char* key, const std::string& where, std::int64_t fallback = -1) const
  {
    const auto found = object.find(key);
    if (found == object.end())
    {
      return fallback;
    }
    if (!found->is_number_integer())
    {
      this->fail(where + "." + key + " is not a whole number");
    }
    return found->get<std::int64_t>();
  }

  /// An optional index into the top-level array `into`; -1 when absent.
  std::int64_t index(const Json& object, const char* key, const char* into, const std::string& where) const
  {
    const std::int64_t value = this->integer(object, key, where);
    if (object.contains(key) && (value < 0 || value >= static_cast<std::int64_t>(this->array(into).size())))
    {
      this->fail(where + "." + key + " = " + std::to_string(value) + " but the file has " +
        std::to_string(this->array(into).size()) + " " + into);
    }
    return value;
  }

  const Json& object(const Json& parent, std::size_t i, const std::string& where) const
  {
    if (!parent[i].is_object())
    {
      this->fail(where + " is not an object");
    }
    return parent[i];
  }

  void run(bool glb, std::int64_t binBytes)
  {
    const auto asset = this->Root.find("asset");
    const std::string version = asset != this->Root.end() && asset->is_object() && asset->contains("version") &&
        (*asset)["version"].is_string()
      ? (*asset)["version"].get<std::string>()
      : std::string();
    if (version.rfind("2.", 0) != 0)
    {
      this->fail(version.empty() ? "it has no asset.version: it is not a glTF 2.0 file"
                                 : "it is glTF version " + printable(version) + ", not 2.x");
    }
    // Extensions a reader must understand: those of materials only change what is not read
    // here (or the emission strength, which is read); geometry compression is not supported.
    for (const auto& required : this->array("extensionsRequired"))
    {
      const std::string name = required.is_string() ? required.get<std::string>() : std::string("?");
      if (name.rfind("KHR_materials_", 0) != 0 && name != "KHR_texture_transform")
      {
        this->fail("it requires the extension " + printable(name) + ", which this reader does not support");
      }
    }
    // Buffers and their views.
    const Json& buffers = this->array("buffers");
    for (std::size_t i = 0; i < buffers.size(); ++i)
    {
      const std::string where = "buffers[" + std::to_string(i) + "]";
      const Json& buffer = this->object(buffers, i, where);
      const std::int64_t length = this->integer(buffer, "byteLength", where);
      if (length < 0 || length > INT32_MAX)
      {
        this->fail(where + ".byteLength is missing or out of range");
      }
      this->BufferBytes.push_back(length);
      const auto uri = buffer.find("uri");
      if (uri == buffer.end())
      {
        if (!glb || i != 0)
        {
          this->fail(where + " has no uri (only the first buffer of a .glb file may lack one)");
        }
        if (binBytes < length)
        {
          this->fail(where + ".byteLength is " + std::to_string(length) + " but the BIN chunk holds " +
            std::to_string(std::max<std::int64_t>(0, binBytes)) + " bytes");
        }
      }
      else if (!uri->is_string())
      {
        this->fail(where + ".uri is not a string");
      }
    }
    const Json& views = this->array("bufferViews");
    for (std::size_t i = 0; i < views.size(); ++i)
    {
      const std::string where = "bufferViews[" + std::to_string(i) + "]";
      const Json& view = this->object(views, i, where);
      if (!view.contains("buffer"))
      {
        this->fail(where + " has no buffer");
      }
      const std::int64_t buffer = this->index(view, "buffer", "buffers", where);
      const std::int64_t offset = this->integer(view, "byteOffset", where, 0);
      const std::int64_t length = this->integer(view, "byteLength", where);
      const std::int64_t stride = this->integer(view, "byteStride", where, 0);
      if (offset < 0 || length < 0 || offset + length > this->BufferBytes[static_cast<std::size_t>(buffer)])
      {
        this->fail(where + " (bytes " + std::to_string(offset) + " to " + std::to_string(offset + length) +
          ") does not fit in buffer " + std::to_string(buffer) + " (" +
          std::to_string(this->BufferBytes[static_cast<std::size_t>(buffer)]) + " bytes)");
      }
      if (view.contains("byteStride") && (stride < 4 || stride > 252))
      {
        this->fail(where + ".byteStride must be from 4 to 252");
      }
    }
    // Accessors, against their views.
    const Json& accessors = this->array("accessors");
    for (std::size_t i = 0; i < accessors.size(); ++i)
    {
      const std::string where = "accessors[" + std::to_string(i) + "]";
      const Json& accessor = this->object(accessors, i, where);
      if (accessor.contains("sparse"))
      {
        this->fail(where + " is sparse: sparse accessors are not supported");
      }
      if (!accessor.contains("bufferView"))
      {
        this->fail(where + " has no bufferView: accessors without data are not supported");
      }
      const Json& view = views[static_cast<std::size_t>(this->index(accessor, "bufferView", "bufferViews", where))];
      const std::int64_t bytes = componentBytes(this->integer(accessor, "componentType", where, 0));
      const auto type = accessor.find("type");
      const std::int64_t components = type != accessor.end() && type->is_string() ? typeComponents(*type) : 0;
      const std::int64_t count = this->integer(accessor, "count", where, 0);
      const std::int64_t offset = this->integer(accessor, "byteOffset", where, 0);
      if (bytes == 0 || components == 0 || count < 1 || offset < 0)
      {
        this->fail(where + " has a missing or invalid componentType, type, count or byteOffset");
      }
      const std::int64_t element = bytes * components;
      const std::int64_t stride = std::max(this->integer(view, "byteStride", where, 0), element);
      const std::int64_t end = offset + (count - 1) * stride + element;
      const std::int64_t available = view["byteLength"].get<std::int64_t>();
      if (count > INT32_MAX / stride || end > available)
      {
        this->fail(where + " (" + std::to_string(count) + " elements of " + std::to_string(element) +
          " bytes from byte " + std::to_string(offset) + ") does not fit in its bufferView (" +
          std::to_string(available) + " bytes)");
      }
      this->AccessorType.push_back(*type);
      this->AccessorComponent.push_back(this->integer(accessor, "componentType", where, 0));
    }
    // Meshes.
    const Json& meshes = this->array("meshes");
    for (std::size_t m = 0; m < meshes.size(); ++m)
    {
      const std::string mesh = "meshes[" + std::to_string(m) + "]";
      const auto primitives = this->object(meshes, m, mesh).find("primitives");
      if (primitives == meshes[m].end() || !primitives->is_array())
      {
        this->fail(mesh + " has no primitives array");
      }
      for (std::size_t p = 0; p < primitives->size(); ++p)
      {
        const std::string where = mesh + ".primitives[" + std::to_string(p) + "]";
        const Json& primitive = this->object(*primitives, p, where);
        const auto attributes = primitive.find("attributes");
        if (attributes == primitive.end() || !attributes->is_object() || !attributes->contains("POSITION"))
        {
          this->fail(where + " has no POSITION attribute");
        }
        for (const auto& attribute : attributes->items())
        {
          const std::int64_t a = this->index(*attributes, attribute.key().c_str(), "accessors", where + ".attributes");
          if (attribute.key() == "POSITION" &&
            (this->AccessorType[static_cast<std::size_t>(a)] != "VEC3" || this->AccessorComponent[static_cast<std::size_t>(a)] != 5126))
          {
            this->fail(where + ".attributes.POSITION is not a VEC3 of floats");
          }
        }
        const std::int64_t indices = this->index(primitive, "indices", "accessors", where);
        if (indices >= 0 &&
          (this->AccessorType[static_cast<std::size_t>(indices)] != "SCALAR" ||
            (this->AccessorComponent[static_cast<std::size_t>(indices)] != 5121 &&
              this->AccessorComponent[static_cast<std::size_t>(indices)] != 5123 &&
              this->AccessorComponent[static_cast<std::size_t>(indices)] != 5125)))
        {
          this->fail(where + ".indices is not a SCALAR of unsigned integers");
        }
        this->index(primitive, "material", "materials", where);
        const std::int64_t mode = this->integer(primitive, "mode", where, 4);
        if (mode < 0 || mode > 6)
        {
          this->fail(where + ".mode = " + std::to_string(mode) + " is not a glTF primitive mode (0 to 6)");
        }
        const auto targets = primitive.find("targets");
        if (targets != primitive.end())
        {
          if (!targets->is_array())
          {
            this->fail(where + ".targets is not an array");
          }
          for (const auto& target : *targets)
          {
            if (!target.is_object())
            {
              this->fail(where + ".targets holds a non-object");
            }
            for (const auto& attribute : target.items())
            {
              this->index(target, attribute.key().c_str(), "accessors", where + ".targets");
            }
          }
        }
      }
    }
    // Materials' textures, textures' images and samplers, images' views.
    const Json& materials = this->array("materials");
    for (std::size_t i = 0; i < materials.size(); ++i)
    {
      const std::string where = "materials[" + std::to_string(i) + "]";
      const Json& material = this->object(materials, i, where);
      auto textureOf = [&](const Json& holder, const char* key, const std::string& at) {
        const auto info = holder.find(key);
        if (info != holder.end())
        {
          if (!info->is_object() || !info->contains("index"))
          {
            this->fail(at + "." + key + " has no texture index");
          }
          this->index(*info, "index", "textures", at + "." + key);
        }
      };
      for (const char* key : { "normalTexture", "occlusionTexture", "emissiveTexture" })
      {
        textureOf(material, key, where);
      }
      const auto pbr = material.find("pbrMetallicRoughness");
      if (pbr != material.end() && pbr->is_object())
      {
        textureOf(*pbr, "baseColorTexture", where + ".pbrMetallicRoughness");
        textureOf(*pbr, "metallicRoughnessTexture", where + ".pbrMetallicRoughness");
      }
    }
    const Json& textures = this->array("textures");
    for (std::size_t i = 0; i < textures.size(); ++i)
    {
      const std::string where = "textures[" + std::to_string(i) + "]";
      this->index(this->object(textures, i, where), "source", "images", where);
      this->index(textures[i], "sampler", "samplers", where);
    }
    const Json& images = this->array("images");
    for (std::size_t i = 0; i < images.size(); ++i)
    {
      const std::string where = "images[" + std::to_string(i) + "]";
      const Json& image = this->object(images, i, where);
      if (this->index(image, "bufferView", "bufferViews", where) >= 0)
      {
        const auto mime = image.find("mimeType");
        if (mime == image.end() || !mime->is_string() || (*mime != "image/png" && *mime != "image/jpeg"))
        {
          this->fail(where + " is in a bufferView but its mimeType is not image/png or image/jpeg");
        }
      }
      else if (!image.contains("uri") || !image["uri"].is_string())
      {
        this->fail(where + " has neither a uri nor a bufferView");
      }
    }
    // Nodes: indices in range, each node with at most one parent, no cycles.
    const Json& nodes = this->array("nodes");
    std::vector<std::int64_t> parent(nodes.size(), -1);
    for (std::size_t i = 0; i < nodes.size(); ++i)
    {
      const std::string where = "nodes[" + std::to_string(i) + "]";
      const Json& node = this->object(nodes, i, where);
      this->index(node, "mesh", "meshes", where);
      this->index(node, "skin", "skins", where);
      this->index(node, "camera", "cameras", where);
      const auto children = node.find("children");
      if (children == node.end())
      {
        continue;
      }
      if (!children->is_array())
      {
        this->fail(where + ".children is not an array");
      }
      for (const auto& child : *children)
      {
        if (!child.is_number_integer() || child.get<std::int64_t>() < 0 ||
          child.get<std::int64_t>() >= static_cast<std::int64_t>(nodes.size()))
        {
          this->fail(where + ".children names a node the file does not have");
        }
        auto& childParent = parent[child.get<std::size_t>()];
        if (childParent >= 0 || child.get<std::size_t>() == i)
        {
          this->fail("node " + std::to_string(child.get<std::int64_t>()) + " has two parents or is its own child");
        }
        childParent = static_cast<std::int64_t>(i);
      }
    }
    for (std::size_t i = 0; i < nodes.size(); ++i)
    {
      std::size_t steps = 0;
      for (std::int64_t up = parent[i]; up >= 0; up = parent[static_cast<std::size_t>(up)])
      {
        if (++steps > nodes.size())
        {
          this->fail("the node hierarchy has a cycle through node " + std::to_string(i));
        }
      }
    }
    this->Parents = parent;
    const Json& scenes = this->array("scenes");
    for (std::size_t i = 0; i < scenes.size(); ++i)
    {
      const std::string where = "scenes[" + std::to_string(i) + "]";
      const auto list = this->object(scenes, i, where).find("nodes");
      if (list == scenes[i].end())
      {
        continue;
      }
      if (!list->is_array())
      {
        this->fail(where + ".nodes is not an array");
      }
      for (const auto& node : *list)
      {
        if (!node.is_number_integer() || node.get<std::int64_t>() < 0 ||
          node.get<std::int64_t>() >= static_cast<std::int64_t>(nodes.size()))
        {
          this->fail(where + ".nodes names a node the file does not have");
        }
      }
    }
    this->index(this->Root, "scene", "scenes", "the file");
    // Skins and animations read accessors and nodes too.
    const Json& skins = this->array("skins");
    for (std::size_t i = 0; i < skins.size(); ++i)
    {
      const std::string where = "skins[" + std::to_string(i) + "]";
      const Json& skin = this->object(skins, i, where);
      this->index(skin, "inverseBindMatrices", "accessors", where);
      this->index(skin, "skeleton", "nodes", where);
      const auto joints = skin.find("joints");
      if (joints == skin.end() || !joints->is_array())
      {
        this->fail(where + " has no joints array");
      }
      for (const auto& joint : *joints)
      {
        if (!joint.is_number_integer() || joint.get<std::int64_t>() < 0 ||
          joint.get<std::int64_t>() >= static_cast<std::int64_t>(nodes.size()))
        {
          this->fail(where + ".joints names a node the file does not have");
        }
      }
    }
    const Json& animations = this->array("animations");
    for (std::size_t i = 0; i < animations.size(); ++i)
    {
      const std::string where = "animations[" + std::to_string(i) + "]";
      const Json& animation = this->object(animations, i, where);
      const auto samplers = animation.find("samplers");
      const auto channels = animation.find("channels");
      if (samplers == animation.end() || !samplers->is_array() || channels == animation.end() ||
        !channels->is_array())
      {
        this->fail(where + " has no samplers or channels array");
      }
      for (const auto& sampler : *samplers)
      {
        if (!sampler.is_object() || !sampler.contains("input") || !sampler.contains("output"))
        {
          this->fail(where + " has a sampler without input or output");
        }
        this->index(sampler, "input", "accessors", where + ".samplers");
        this->index(sampler, "output", "accessors", where + ".samplers");
      }
      for (const auto& channel : *channels)
      {
        const std::int64_t sampler = channel.is_object() ? this->integer(channel, "sampler", where, -1) : -1;
        if (sampler < 0 || sampler >= static_cast<std::int64_t>(samplers->size()))
        {
          this->fail(where + " has a channel without a valid sampler");
        }
        const auto target = channel.find("target");
        if (target == channel.end() || !target->is_object())
        {
          this->fail(where + " has a channel without a target");
        }
        this->index(*target, "node", "nodes", where + ".channels.target");
      }
    }
  }

  std::vector<std::int64_t> Parents;

private:
  const Json& Root;
  std::string Path;
  std::vector<std::int64_t> BufferBytes;
  std::vector<std::string> AccessorType;
  std::vector<std::int64_t> AccessorComponent;
};

std::uint32_t littleEndian32(const unsigned char* bytes)
{
  return static_cast<std::uint32_t>(bytes[0]) | (static_cast<std::uint32_t>(bytes[1]) << 8) |
    (static_cast<std::uint32_t>(bytes[2]) << 16) | (static_cast<std::uint32_t>(bytes[3]) << 24);
}

/// The JSON of a .gltf file, or of a .glb file's first chunk (and its BIN chunk in `bin`;
/// binBytes is its size, -1 without one).
Json readGltfJson(const std::string& path, bool glb, std::string& bin, std::int64_t& binBytes)
{
  std::ifstream in = openFile(path, "glTF file");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  binBytes = -1;
  auto fail = [&](const std::string& problem) {
    throw FileError("the glTF file " + named(path) + " " + problem);
  };
  if (glb)
  {
    const auto* bytes = reinterpret_cast<const unsigned char*>(text.data());
    if (text.size() < 20 || text.compare(0, 4, "glTF") != 0)
    {
      fail("is not a binary glTF (.glb) file: it does not start with 'glTF'");
    }
    if (littleEndian32(bytes + 4) != 2)
    {
      fail("is binary glTF version " + std::to_string(littleEndian32(bytes + 4)) + ", not 2");
    }
    if (littleEndian32(bytes + 8) != text.size())
    {
      fail("says it holds " + std::to_string(littleEndian32(bytes + 8)) + " bytes but has " +
        std::to_string(text.size()) + ": it is truncated or damaged");
    }
    const std::uint64_t jsonBytes = littleEndian32(bytes + 12);
    if (text.compare(16, 4, "JSON") != 0 || 20 + jsonBytes > text.size())
    {
      fail("has no complete JSON chunk first");
    }
    // The chunks must tile the file exactly, as vtkGLTFDocumentLoader assumes.
    std::uint64_t at = 20 + jsonBytes;
    while (at < text.size())
    {
      if (at + 8 > text.size())
      {
        fail("ends inside a chunk header: it is truncated or damaged");
      }
      const std::uint64_t chunk = littleEndian32(bytes + at);
      if (at + 8 + chunk > text.size())
      {
        fail("has a chunk longer than the file: it is truncated or damaged");
      }
      if (text.compare(at + 4, 4, std::string("BIN\0", 4)) == 0 && binBytes < 0)
      {
        binBytes = static_cast<std::int64_t>(chunk);
        bin = text.substr(at + 8, chunk);
      }
      at += 8 + chunk;
    }
    text = text.substr(20, jsonBytes);
  }
  try
  {
    Json root = Json::parse(text);
    if (!root.is_object())
    {
      fail("is not a glTF document: its JSON is not an object");
    }
    return root;
  }
  catch (const Json::exception& e)
  {
    fail(std::string("is not valid JSON: ") + e.what());
  }
  return {};
}

/// Decodes standard base64 (the payload of a data: URI); false on a character outside it.
bool decodeBase64(const std::string& text, std::string& bytes)
{
  bytes.clear();
  std::uint32_t chunk = 0;
  int bits = 0;
  for (char c : text)
  {
    int value = -1;
    if (c >= 'A' && c <= 'Z')
    {
      value = c - 'A';
    }
    else if (c >= 'a' && c <= 'z')
    {
      value = c - 'a' + 26;
    }
    else if (c >= '0' && c <= '9')
    {
      value = c - '0' + 52;
    }
    else if (c == '+' || c == '-')
    {
      value = 62;
    }
    else if (c == '/' || c == '_')
    {
      value = 63;
    }
    else if (c == '=' || std::isspace(static_cast<unsigned char>(c)))
    {
      continue;
    }
    if (value < 0)
    {
      return false;
    }
    chunk = (chunk << 6) | static_cast<std::uint32_t>(value);
    bits += 6;
    if (bits >= 8)
    {
      bits -= 8;
      bytes += static_cast<char>((chunk >> bits) & 0xff);
    }
  }
  return true;
}

/// A relative URI of a glTF resource as a path: %XX escapes decoded.
std::string uriPath(const std::string& uri)
{
  std::string path;
  for (std::size_t i = 0; i < uri.size(); ++i)
  {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
      std::isxdigit(static_cast<unsigned char>(uri[i + 2])))
    {
      path += static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    }
    else
    {
      path += uri[i];
    }
  }
  return path;
}

/// One component of an accessor; a normalized integer maps to [0, 1] (unsigned) or [-1, 1].
template <typename T>
double component(const char* at, bool normalized)
{
  T value;
  std::memcpy(&value, at, sizeof(T));
  if (!normalized)
  {
    return static_cast<double>(value);
  }
  return std::max(static_cast<double>(value) / static_cast<double>(std::numeric_limits<T>::max()), -1.0);
}

/// A glTF document whose indices and sizes GltfChecks has checked: buffers loaded, accessors
/// read as numbers.
class GltfDocument
{
public:
  GltfDocument(const Json& root, const std::string& path, std::string bin)
    : Root(root)
    , Path(path)
    , Folder(std::filesystem::path(path).parent_path())
  {
    const Json& buffers = root.contains("buffers") ? root["buffers"] : Json::array();
    for (std::size_t i = 0; i < buffers.size(); ++i)
    {
      const std::size_t length = buffers[i]["byteLength"].get<std::size_t>();
      std::string bytes;
      if (!buffers[i].contains("uri"))
      {
        bytes = bin; // GltfChecks: only buffer 0 of a .glb, and the BIN chunk holds byteLength
      }
      else
      {
        bytes = this->resource(buffers[i]["uri"].get<std::string>(), "buffers[" + std::to_string(i) + "]");
      }
      if (bytes.size() < length)
      {
        this->fail("buffers[" + std::to_string(i) + "] holds " + std::to_string(bytes.size()) +
          " bytes, less than its byteLength " + std::to_string(length));
      }
      this->Buffers.push_back(std::move(bytes));
    }
  }

  [[noreturn]] void fail(const std::string& problem) const
  {
    throw FileError("the glTF file " + named(this->Path) + ": " + problem);
  }

  /// The bytes of a data: URI or of a file beside the glTF file.
  std::string resource(const std::string& uri, const std::string& what) const
  {
    if (uri.rfind("data:", 0) == 0)
    {
      const auto comma = uri.find(',');
      std::string bytes;
      if (comma == std::string::npos || uri.substr(0, comma).find(";base64") == std::string::npos ||
        !decodeBase64(uri.substr(comma + 1), bytes))
      {
        this->fail(what + " has a data: URI that is not base64");
      }
      return bytes;
    }
    const std::filesystem::path file = this->Folder / uriPath(uri);
    std::error_code error;
    if (!std::filesystem::is_regular_file(file, error))
    {
      this->fail(what + " names the file " + named(file.string()) + ", which does not exist");
    }
    const std::uintmax_t size = std::filesystem::file_size(file, error);
    if (error || size > MaxResourceFileBytes)
    {
      this->fail(what + ": the file " + named(file.string()) +
        (error ? " has a size that cannot be read" : " is over the 4 GiB this reader takes"));
    }
    std::ifstream in(file, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad())
    {
      this->fail(what + ": the file " + named(file.string()) + " could not be read");
    }
    return bytes;
  }

  /// The bytes of a buffer view (checked to fit in its buffer).
  std::string view(std::size_t index) const
  {
    const Json& view = this->Root["bufferViews"][index];
    return this->Buffers[view["buffer"].get<std::size_t>()].substr(
      view.value("byteOffset", std::size_t(0)), view["byteLength"].get<std::size_t>());
  }

  /// Accessor `index` as numbers, `components` per element; normalized integers in [0, 1].
  std::vector<double> accessor(std::size_t index, std::size_t& components) const
  {
    const Json& accessor = this->Root["accessors"][index];
    const Json& view = this->Root["bufferViews"][accessor["bufferView"].get<std::size_t>()];
    const std::int64_t type = accessor["componentType"].get<std::int64_t>();
    const std::size_t bytes = static_cast<std::size_t>(componentBytes(type));
    components = static_cast<std::size_t>(typeComponents(accessor["type"].get<std::string>()));
    const std::size_t count = accessor["count"].get<std::size_t>();
    const std::size_t stride = std::max<std::size_t>(view.value("byteStride", std::size_t(0)), bytes * components);
    const std::string& buffer = this->Buffers[view["buffer"].get<std::size_t>()];
    const std::size_t start = view.value("byteOffset", std::size_t(0)) + accessor.value("byteOffset", std::size_t(0));
    const bool normalized = accessor.value("normalized", false);
    std::vector<double> values(count * components);
    for (std::size_t e = 0; e < count; ++e)
    {
      for (std::size_t c = 0; c < components; ++c)
      {
        const char* at = buffer.data() + start + e * stride + c * bytes;
        double value = 0;
        switch (type)
        {
          case 5120:
            value = component<std::int8_t>(at, normalized);
            break;
          case 5121:
            value = component<std::uint8_t>(at, normalized);
            break;
          case 5122:
            value = component<std::int16_t>(at, normalized);
            break;
          case 5123:
            value = component<std::uint16_t>(at, normalized);
            break;
          case 5125:
            value = component<std::uint32_t>(at, false);
            break;
          default:
            value = component<float>(at, false);
        }
        values[e * components + c] = value;
      }
    }
    return values;
  }

  /// The mean linear colour of texture `texture` (sRGB-encoded, as base colour and emissive
  /// textures are); (1, 1, 1) with a warning when its image cannot be decoded.
  std::array<double, 3> textureMean(std::size_t texture, const std::string& what, const Warn& warn) const
  {
    const Json& entry = this->Root["textures"][texture];
    std::string problem;
    std::optional<std::array<double, 3>> mean;
    if (!entry.contains("source"))
    {
      problem = "its texture has no image";
    }
    else
    {
      const Json& source = this->Root["images"][entry["source"].get<std::size_t>()];
      std::string bytes;
      if (source.contains("bufferView"))
      {
        bytes = this->view(source["bufferView"].get<std::size_t>());
      }
      else
      {
        bytes = this->resource(source["uri"].get<std::string>(), what + "'s image");
      }
      mean = imageMean(bytes, problem);
    }
    if (!mean)
    {
      warn(what + ": " + problem + ", so its factor alone is used");
      return { { 1, 1, 1 } };
    }
    return *mean;
  }

  /// The local transform of node `index`: its matrix, or translation x rotation x scale.
  std::array<double, 16> localTransform(std::size_t index) const
  {
    const Json& node = this->Root["nodes"][index];
    const std::string where = "nodes[" + std::to_string(index) + "]";
    auto numbers = [&](const char* key, std::size_t size, std::vector<double> fallback) {
      const auto found = node.find(key);
      if (found == node.end())
      {
        return fallback;
      }
      if (!found->is_array() || found->size() != size)
      {
        this->fail(where + "." + key + " is not " + std::to_string(size) + " numbers");
      }
      std::vector<double> values;
      for (const auto& value : *found)
      {
        if (!value.is_number() || !std::isfinite(value.get<double>()))
        {
          this->fail(where + "." + key + " is not " + std::to_string(size) + " finite numbers");
        }
        values.push_back(value.get<double>());
      }
      return values;
    };
    std::array<double, 16> m{}; // row-major
    if (node.contains("matrix"))
    {
      const auto columnMajor = numbers("matrix", 16, {});
      for (std::size_t r = 0; r < 4; ++r)
      {
        for (std::size_t c = 0; c < 4; ++c)
        {
          m[4 * r + c] = columnMajor[4 * c + r];
        }
      }
      return m;
    }
    const auto t = numbers("translation", 3, { 0, 0, 0 });
    const auto q = numbers("rotation", 4, { 0, 0, 0, 1 });
    const auto s = numbers("scale", 3, { 1, 1, 1 });
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (norm == 0)
    {
      this->fail(where + ".rotation is a zero quaternion");
    }
    const double x = q[0] / norm, y = q[1] / norm, z = q[2] / norm, w = q[3] / norm;
    const double r[3][3] = { { 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w) },
      { 2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w) },
      { 2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y) } };
    for (std::size_t i = 0; i < 3; ++i)
    {
      for (std::size_t j = 0; j < 3; ++j)
      {
        m[4 * i + j] = r[i][j] * s[j];
      }
      m[4 * i + 3] = t[i];
    }
    m[15] = 1;
    return m;
  }

private:
  const Json& Root;
  std::string Path;
  std::filesystem::path Folder;
  std::vector<std::string> Buffers;
};

std::array<double, 16> multiply(const std::array<double, 16>& a, const std::array<double, 16>& b)
{
  std::array<double, 16> m{};
  for (std::size_t r = 0; r < 4; ++r)
  {
    for (std::size_t c = 0; c < 4; ++c)
    {
      for (std::size_t k = 0; k < 4; ++k)
      {
        m[4 * r + c] += a[4 * r + k] * b[4 * k + c];
      }
    }
  }
  return m;
}

/// A colour factor of a material: `size` numbers (glTF keeps them in [0, 1]; emission
/// strength scales emissiveFactor).
std::array<double, 3> colourFactor(const Json& holder, const char* key, std::size_t size,
  double fallback, const std::string& what, const std::function<void(const std::string&)>& fail)
{
  std::array<double, 3> rgb{ { fallback, fallback, fallback } };
  const auto found = holder.find(key);
  if (found == holder.end())
  {
    return rgb;
  }
  if (!found->is_array() || found->size() != size)
  {
    fail(what + "." + key + " is not " + std::to_string(size) + " numbers");
  }
  for (std::size_t c = 0; c < 3; ++c)
  {
    const Json& value = (*found)[c];
    if (!value.is_number() || !std::isfinite(value.get<double>()) || value.get<double>() < 0)
    {
      fail(what + "." + key + " must hold numbers, 0 or more");
    }
    rgb[c] = value.get<double>();
  }
  return rgb;
}
Scene readGltfDocument(const Json& root, const std::string& path, bool glb, std::string bin,
  std::int64_t binBytes, const Warn& warn, ProgressPoll& poll)
{
  GltfChecks checks(root, path);
  checks.run(glb, binBytes);
  std::size_t surfaces = 0, others = 0;
  for (const auto& mesh : checks.array("meshes"))
  {
    for (const auto& primitive : mesh["primitives"])
    {
      (checks.integer(primitive, "mode", "a primitive", 4) >= 4 ? surfaces : others) += 1;
    }
  }
  if (surfaces == 0)
  {
    throw FileError("the glTF file " + named(path) + " has no triangles" +
      (others > 0 ? " (only points or lines: " + std::to_string(others) + " primitives)" : std::string()) +
      ": there is no surface to light");
  }
  poll(0.1);
  const GltfDocument document(root, path, std::move(bin));
  poll(0.3);

  // The nodes to draw: the default scene's (or the first scene's), else every root node.
  std::vector<std::int64_t> roots;
  const Json& scenes = checks.array("scenes");
  if (!scenes.empty())
  {
    const std::size_t scene = static_cast<std::size_t>(std::max<std::int64_t>(0, checks.integer(root, "scene", "the file", 0)));
    for (const auto& node : scenes[scene].value("nodes", Json::array()))
    {
      roots.push_back(node.get<std::int64_t>());
    }
  }
  else
  {
    for (std::size_t i = 0; i < checks.Parents.size(); ++i)
    {
      if (checks.Parents[i] < 0)
      {
        roots.push_back(static_cast<std::int64_t>(i));
      }
    }
  }

  Scene scene;
  scene.format = "glTF";
  scene.points = vtkSmartPointer<vtkPoints>::New();
  scene.points->SetDataTypeToDouble();
  scene.polygons = vtkSmartPointer<vtkCellArray>::New();
  std::map<std::int64_t, int> materialIds; // glTF material (-1: the default) -> output material
  std::vector<std::int64_t> materialOrder;
  std::vector<std::array<double, 3>> vertexColourOfCell;
  bool anyColour = false;
  std::size_t skippedPrimitives = 0;
  const Json& nodes = checks.array("nodes");
  const Json& meshes = checks.array("meshes");

  // Depth first, with the transform down to each node (the hierarchy is a checked forest).
  std::array<double, 16> identity{};
  identity[0] = identity[5] = identity[10] = identity[15] = 1;
  std::vector<std::pair<std::size_t, std::array<double, 16>>> stack;
  std::size_t visited = 0;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it)
  {
    stack.emplace_back(static_cast<std::size_t>(*it), identity);
  }
  while (!stack.empty())
  {
    const auto [nodeIndex, parent] = stack.back();
    stack.pop_back();
    poll(0.3 + 0.6 * static_cast<double>(visited++) / static_cast<double>(std::max<std::size_t>(1, nodes.size())));
    const Json& node = nodes[nodeIndex];
    const std::array<double, 16> matrix = multiply(parent, document.localTransform(nodeIndex));
    const Json children = node.value("children", Json::array());
    for (auto child = children.rbegin(); child != children.rend(); ++child)
    {
      stack.emplace_back(child->get<std::size_t>(), matrix);
    }
    if (!node.contains("mesh"))
    {
      continue;
    }
    const std::size_t meshIndex = node["mesh"].get<std::size_t>();
    for (const Json& primitive : meshes[meshIndex]["primitives"])
    {
      const std::int64_t mode = primitive.value("mode", std::int64_t(4));
      if (mode < 4)
      {
        ++skippedPrimitives;
        continue;
      }
      const Json& attributes = primitive["attributes"];
      std::size_t components = 0;
      const std::vector<double> positions = document.accessor(attributes["POSITION"].get<std::size_t>(), components);
      const std::size_t vertexCount = positions.size() / 3;
      std::vector<std::size_t> indices;
      if (primitive.contains("indices"))
      {
        for (double index : document.accessor(primitive["indices"].get<std::size_t>(), components))
        {
          if (index >= static_cast<double>(vertexCount))
          {
            document.fail("a primitive of meshes[" + std::to_string(meshIndex) + "] names vertex " +
              std::to_string(static_cast<std::uint64_t>(index)) + " but its POSITION has " +
              std::to_string(vertexCount));
          }
          indices.push_back(static_cast<std::size_t>(index));
        }
      }
      else
      {
        for (std::size_t i = 0; i < vertexCount; ++i)
        {
          indices.push_back(i);
        }
      }
      std::vector<std::array<std::size_t, 3>> triangles;
      for (std::size_t i = 0; i + 2 < indices.size(); i += mode == 4 ? 3 : 1)
      {
        if (mode == 4)
        {
          triangles.push_back({ { indices[i], indices[i + 1], indices[i + 2] } });
        }
        else if (mode == 5) // strip: every other triangle turns the other way
        {
          triangles.push_back(i % 2 == 0 ? std::array<std::size_t, 3>{ { indices[i], indices[i + 1], indices[i + 2] } }
                                         : std::array<std::size_t, 3>{ { indices[i + 1], indices[i], indices[i + 2] } });
        }
        else // fan
        {
          triangles.push_back({ { indices[0], indices[i + 1], indices[i + 2] } });
        }
      }
      const std::int64_t gltfMaterial = primitive.value("material", std::int64_t(-1));
      const auto found = materialIds.find(gltfMaterial);
      int material = 0;
      if (found != materialIds.end())
      {
        material = found->second;
      }
      else
      {
        material = static_cast<int>(materialOrder.size());
        materialIds[gltfMaterial] = material;
        materialOrder.push_back(gltfMaterial);
      }
      std::vector<double> colours;
      std::size_t colourComponents = 0;
      if (attributes.contains("COLOR_0"))
      {
        colours = document.accessor(attributes["COLOR_0"].get<std::size_t>(), colourComponents);
        if (colourComponents < 3 || colours.size() / colourComponents != vertexCount)
        {
          document.fail("a primitive of meshes[" + std::to_string(meshIndex) +
            "] has a COLOR_0 that is not one RGB or RGBA colour per vertex");
        }
      }
      const vtkIdType offset = scene.points->GetNumberOfPoints();
      for (std::size_t v = 0; v < vertexCount; ++v)
      {
        double p[3];
        for (std::size_t r = 0; r < 3; ++r)
        {
          p[r] = matrix[4 * r] * positions[3 * v] + matrix[4 * r + 1] * positions[3 * v + 1] +
            matrix[4 * r + 2] * positions[3 * v + 2] + matrix[4 * r + 3];
        }
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
        {
          document.fail("meshes[" + std::to_string(meshIndex) + "] has a vertex that is not a finite point");
        }
        scene.points->InsertNextPoint(p);
      }
      for (const auto& triangle : triangles)
      {
        const vtkIdType ids[3] = { offset + static_cast<vtkIdType>(triangle[0]),
          offset + static_cast<vtkIdType>(triangle[1]), offset + static_cast<vtkIdType>(triangle[2]) };
        scene.polygons->InsertNextCell(3, ids);
        scene.materialOfCell.push_back(material);
        std::array<double, 3> mean{ { 1, 1, 1 } };
        if (!colours.empty())
        {
          anyColour = true;
          for (std::size_t c = 0; c < 3; ++c)
          {
            mean[c] = (colours[triangle[0] * colourComponents + c] + colours[triangle[1] * colourComponents + c] +
                        colours[triangle[2] * colourComponents + c]) / 3.0;
          }
        }
        vertexColourOfCell.push_back(mean);
      }
    }
  }
  if (scene.polygons->GetNumberOfCells() == 0)
  {
    throw FileError("the glTF file " + named(path) + " has no triangles in its scene" +
      (skippedPrimitives > 0 ? " (only points or lines: " + std::to_string(skippedPrimitives) + " primitives)" : std::string()) +
      ": there is no surface to light");
  }
  if (skippedPrimitives > 0)
  {
    warn("the glTF file " + named(path) + " has " + std::to_string(skippedPrimitives) +
      " primitives of points or lines: they are skipped, only triangles are surfaces");
  }
  if (root.contains("skins") || root.contains("animations") || root.contains("extensionsRequired"))
  {
    // Morph targets, skins and animations move vertices; the rest pose is what is read.
    if (!checks.array("skins").empty() || !checks.array("animations").empty())
    {
      warn("the glTF file " + named(path) + " has skins or animations: the meshes are read in their rest pose");
    }
  }

  // Materials, in order of first use; names unique (glTF names are optional and may repeat).
  const Json& materials = checks.array("materials");
  std::set<std::string> names;
  auto failMaterial = [&](const std::string& problem) { document.fail(problem); };
  for (const std::int64_t gltfIndex : materialOrder)
  {
    Material material;
    if (gltfIndex < 0)
    {
      material.name = "default";
      material.reflectance = checkedReflectance({ { 1, 1, 1 } },
        "the glTF default material (of primitives without a material) in " + named(path), warn);
    }
    else
    {
      const Json& source = materials[static_cast<std::size_t>(gltfIndex)];
      const std::string where = "materials[" + std::to_string(gltfIndex) + "]";
      const auto name = source.find("name");
      material.name = name != source.end() && name->is_string() && !name->get<std::string>().empty()
        ? name->get<std::string>()
        : "material_" + std::to_string(gltfIndex);
      const std::string what = "the glTF material " + named(material.name) + " of " + named(path);
      const Json pbr = source.value("pbrMetallicRoughness", Json::object());
      std::array<double, 3> base = colourFactor(pbr, "baseColorFactor", 4, 1.0, where + ".pbrMetallicRoughness", failMaterial);
      if (pbr.contains("baseColorTexture"))
      {
        const auto mean = document.textureMean(pbr["baseColorTexture"]["index"].get<std::size_t>(), what, warn);
        for (std::size_t c = 0; c < 3; ++c)
        {
          base[c] *= mean[c];
        }
      }
      material.reflectance = checkedReflectance(base, what, warn);
      double strength = 1.0;
      const Json extension = source.value("extensions", Json::object()).value("KHR_materials_emissive_strength", Json::object());
      if (extension.contains("emissiveStrength"))
      {
        const Json& value = extension["emissiveStrength"];
        if (!value.is_number() || !std::isfinite(value.get<double>()) || value.get<double>() < 0)
        {
          document.fail(where + ".extensions.KHR_materials_emissive_strength.emissiveStrength must be a number, 0 or more");
        }
        strength = value.get<double>();
      }
      material.radiance = colourFactor(source, "emissiveFactor", 3, 0.0, where, failMaterial);
      for (double& value : material.radiance)
      {
        value *= strength;
      }
      if (source.contains("emissiveTexture") && material.radiance != std::array<double, 3>{ { 0, 0, 0 } })
      {
        const auto mean = document.textureMean(source["emissiveTexture"]["index"].get<std::size_t>(), what, warn);
        for (std::size_t c = 0; c < 3; ++c)
        {
          material.radiance[c] *= mean[c];
        }
      }
    }
    std::string unique = material.name;
    for (int n = 2; !names.insert(unique).second; ++n)
    {
      unique = material.name + "_" + std::to_string(n);
    }
    material.name = unique;
    scene.materials.push_back(material);
  }
  if (anyColour)
  {
    std::size_t clamped = 0;
    scene.cellReflectance.resize(vertexColourOfCell.size());
    for (std::size_t cell = 0; cell < vertexColourOfCell.size(); ++cell)
    {
      const auto& base = scene.materials[static_cast<std::size_t>(scene.materialOfCell[cell])].reflectance;
      for (std::size_t c = 0; c < 3; ++c)
      {
        const double value = std::max(0.0, base[c] * vertexColourOfCell[cell][c]);
        clamped += value > MaxReflectance ? 1 : 0;
        scene.cellReflectance[cell][c] = std::min(value, MaxReflectance);
      }
    }
    if (clamped > 0)
    {
      warn("the glTF file " + named(path) + ": " + std::to_string(clamped) +
        " reflectance components of cells coloured by COLOR_0 are clamped to 0.99");
    }
  }
  poll(1.0);
  return scene;
}

} // namespace

Scene readGltf(const std::string& path, const Warn& warn, const Progress& progress)
{
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const bool glb = extension == ".glb";
  ProgressPoll poll(progress, 0.0, 1.0);

  std::string bin;
  std::int64_t binBytes = -1;
  const Json root = readGltfJson(path, glb, bin, binBytes);
  try
  {
    return readGltfDocument(root, path, glb, std::move(bin), binBytes, warn, poll);
  }
  catch (const Json::exception& e)
  {
    // A member of an unexpected JSON type that the checks above did not look at.
    throw FileError("the glTF file " + named(path) + " is malformed: " + e.what());
  }
}

// =========================================================================================
// PLY
// =========================================================================================

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
        throw FileError("the PLY file " + named(this->Path) + ": '" + printable(word) + "' (" + what +
          ") is not a finite number");
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
      value = static_cast<double>(static_cast<std::int64_t>((bits ^ sign)) - static_cast<std::int64_t>(sign));
    }
    else
    {
      value = static_cast<double>(bits);
    }
    if (!std::isfinite(value))
    {
      throw FileError("the PLY file " + named(this->Path) + ": " + what + " is not a finite number");
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

Scene readPly(const std::string& path, const Warn& warn, const Progress& progress)
{
  std::ifstream in = openFile(path, "PLY file");
  ProgressPoll poll(progress, 0.0, 0.9);
  auto fail = [&](const std::string& problem) {
    throw FileError("the PLY file " + named(path) + " " + problem);
  };
  std::string line;
  if (!std::getline(in, line) || trim(line) != "ply")
  {
    fail("is not a PLY file: it does not start with 'ply'");
  }
  std::vector<PlyElement> elements;
  PlyFormat format = PlyFormat::Ascii;
  bool hasFormat = false, ended = false;
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
      if (parts.size() < 2 || (parts[1] != "ascii" && parts[1] != "binary_little_endian" && parts[1] != "binary_big_endian"))
      {
        fail("has an unknown format, " + where);
      }
      format = parts[1] == "ascii" ? PlyFormat::Ascii
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
      if (parts.size() == 5 && parts[1] == "list" && plyBytes(parts[2]) && plyBytes(parts[3]) && !plyIsFloat(parts[2]))
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
      fail("has an unknown header line, " + where);
    }
  }
  if (!ended || !hasFormat)
  {
    fail(ended ? "has no format line" : "has a header without end_header");
  }

  const PlyElement* vertex = nullptr;
  const PlyElement* face = nullptr;
  for (const auto& element : elements)
  {
    vertex = element.name == "vertex" ? &element : vertex;
    face = element.name == "face" ? &element : face;
  }
  if (!vertex || vertex->find("x") < 0 || vertex->find("y") < 0 || vertex->find("z") < 0)
  {
    fail("has no element 'vertex' with properties x, y and z");
  }
  int indexProperty = face ? face->find("vertex_indices") : -1;
  if (face && indexProperty < 0)
  {
    indexProperty = face->find("vertex_index");
  }
  if (!face || face->count == 0 || indexProperty < 0 || !face->properties[static_cast<std::size_t>(indexProperty)].list)
  {
    fail("has no faces (an element 'face' with a list property vertex_indices): there is no surface to light");
  }
  auto colourOf = [](const PlyElement& element, std::array<int, 3>& rgb) {
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
  std::array<int, 3> vertexRgb{}, faceRgb{};
  const bool vertexColours = colourOf(*vertex, vertexRgb);
  const bool faceColours = colourOf(*face, faceRgb);
  for (int axis : { vertex->find("x"), vertex->find("y"), vertex->find("z") })
  {
    if (vertex->properties[static_cast<std::size_t>(axis)].list)
    {
      fail("has a list property for a vertex coordinate");
    }
  }

  // The body: elements in header order; others are read and dropped.
  const std::uintmax_t size = fileSize(path);
  PlyValues values(in, format, path);
  Scene scene;
  scene.format = "PLY";
  scene.points = vtkSmartPointer<vtkPoints>::New();
  scene.points->SetDataTypeToDouble();
  scene.polygons = vtkSmartPointer<vtkCellArray>::New();
  std::vector<std::array<double, 3>> vertexColour;
  std::vector<double> row;
  std::vector<vtkIdType> ids;
  std::uint64_t rowsRead = 0;
  std::size_t unlistedFaces = 0;
  bool verticesRead = false;
  for (const auto& element : elements)
  {
    const bool isVertex = &element == vertex, isFace = &element == face;
    if (isFace && !verticesRead)
    {
      fail("lists its faces before its vertices: this reader needs the vertices first");
    }
    for (std::uint64_t e = 0; e < element.count; ++e)
    {
      if (++rowsRead % 65536 == 0)
      {
        poll(size > 0 ? static_cast<double>(std::max<std::streamoff>(0, in.tellg())) / static_cast<double>(size) : 0.0);
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
        if (count < 0 || count > 1e6)
        {
          fail("has a list of " + std::to_string(count) + " values in " + what);
        }
        const bool indices = isFace && static_cast<int>(p) == indexProperty;
        if (indices)
        {
          ids.clear();
        }
        for (int k = 0; k < static_cast<int>(count); ++k)
        {
          const double value = values.read(property.type, what + " " + property.name);
          if (indices)
          {
            if (value < 0 || value >= static_cast<double>(scene.points->GetNumberOfPoints()) || value != std::floor(value))
            {
              fail("names vertex " + std::to_string(static_cast<long long>(value)) + " in " + what + " but has " +
                std::to_string(scene.points->GetNumberOfPoints()) + " vertices");
            }
            ids.push_back(static_cast<vtkIdType>(value));
          }
        }
      }
      if (isVertex)
      {
        scene.points->InsertNextPoint(row[static_cast<std::size_t>(vertex->find("x"))],
          row[static_cast<std::size_t>(vertex->find("y"))], row[static_cast<std::size_t>(vertex->find("z"))]);
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
        scene.polygons->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
        std::array<double, 3> rgb{ { FallbackReflectance, FallbackReflectance, FallbackReflectance } };
        if (faceColours)
        {
          for (std::size_t c = 0; c < 3; ++c)
          {
            const auto& property = face->properties[static_cast<std::size_t>(faceRgb[c])];
            rgb[c] = plyColour(row[static_cast<std::size_t>(faceRgb[c])], property.type);
          }
        }
        else if (vertexColours)
        {
          rgb = { { 0, 0, 0 } };
          for (vtkIdType id : ids)
          {
            for (std::size_t c = 0; c < 3; ++c)
            {
              rgb[c] += vertexColour[static_cast<std::size_t>(id)][c] / static_cast<double>(ids.size());
            }
          }
        }
        scene.cellReflectance.push_back(rgb);
      }
    }
    verticesRead = verticesRead || isVertex;
  }
  if (scene.polygons->GetNumberOfCells() == 0)
  {
    fail("has no faces with 3 or more vertices: there is no surface to light");
  }
  if (unlistedFaces > 0)
  {
    warn("the PLY file " + named(path) + " has " + std::to_string(unlistedFaces) +
      " faces with fewer than 3 vertices: they are skipped");
  }
  const std::string stem = std::filesystem::path(path).stem().string();
  if (!faceColours && !vertexColours)
  {
    warn("the PLY file " + named(path) + " has no red/green/blue colours: every surface is grey 0.5");
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
        fail("has a colour above 1: float colours must be from 0 to 1");
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
