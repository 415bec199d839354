// Textures: the mean colour of an image (glTF base colour and emissive textures, MTL map_Kd
// and map_Ke), which multiplies the material's colour. Private to the Filters module.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>

namespace mlr::scenefile
{

/// The mean linear colour of an encoded PNG or JPEG image (sRGB, as colour textures are); no
/// value, and `problem` saying why ("its image is ..."), when it cannot be decoded.
std::optional<std::array<double, 3>> imageMean(const std::string& bytes, std::string& problem);

/// The bytes of a texture file an MTL map names, or false with `problem` ("its file ..."):
/// only a regular file of at most 256 MiB (MaxTextureFileBytes) is read, and only when its
/// first bytes are a PNG or JPEG signature, so that a folder, a device (/dev/zero), a FIFO or
/// a large file of another kind is refused at once.
bool readTextureFile(const std::filesystem::path& file, std::string& bytes, std::string& problem);

} // namespace mlr::scenefile
