#include "SceneTextures.h"

#include "SceneText.h"

#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkJPEGReader.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkSmartPointer.h"

#include "vtk_png.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <vector>

namespace mlr::scenefile
{

namespace
{
/// A texture's mean needs no more than this many texels: larger images are refused rather than
/// risking memory on a damaged header.
constexpr std::uint64_t MaxTexturePixels = std::uint64_t(1) << 26;
/// The largest texture file read (MTL maps): a 64-Mpixel PNG seldom needs more, and a bigger
/// file is refused before any of it is read.
constexpr std::uintmax_t MaxTextureFileBytes = std::uintmax_t(256) << 20;

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
// libjpeg skips stray bytes between segments to find the next marker, so this scan must
// too: stopping at the first stray byte would let a frame header it hides through unchecked.
// No frame header means no size to check, and such an image is refused.
std::optional<std::uint64_t> jpegPixels(const std::string& bytes)
{
  auto byte = [&](std::size_t i)
  { return static_cast<std::uint64_t>(static_cast<unsigned char>(bytes[i])); };
  std::size_t at = 2;
  while (at + 4 <= bytes.size())
  {
    if (byte(at) != 0xff)
    {
      ++at; // extraneous byte
      continue;
    }
    const std::uint64_t marker = byte(at + 1);
    if (marker == 0xff || marker == 0x00)
    {
      ++at; // fill byte, or a stuffed zero outside any scan
      continue;
    }
    if (marker == 0x01 || (marker >= 0xd0 && marker <= 0xd8))
    {
      at += 2; // markers without a length
      continue;
    }
    if (marker == 0xd9 || marker == 0xda)
    {
      return std::nullopt; // end of image or scan data before any frame header
    }
    const bool frame =
      marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
    if (frame)
    {
      if (at + 9 > bytes.size())
      {
        return std::nullopt;
      }
      return ((byte(at + 5) << 8) | byte(at + 6)) * ((byte(at + 7) << 8) | byte(at + 8));
    }
    at += 2 + static_cast<std::size_t>((byte(at + 2) << 8) | byte(at + 3));
  }
  return std::nullopt;
}
} // namespace

std::optional<std::array<double, 3>> imageMean(const std::string& bytes, std::string& problem)
{
  vtkSmartPointer<vtkImageData> image;
  if (isPng(bytes))
  {
    image = decodePng(bytes, problem);
  }
  else if (isJpeg(bytes))
  {
    const std::optional<std::uint64_t> pixels = jpegPixels(bytes);
    if (!pixels)
    {
      problem = "its JPEG image has no readable frame header, so its size is unknown";
      return std::nullopt;
    }
    if (*pixels > MaxTexturePixels)
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
    problem = std::filesystem::is_directory(status) ? "its file is a folder"
                                                    : "its file is not a regular file";
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

} // namespace mlr::scenefile
