// The .pvd + .vtu time series: file names, frames and the collection file.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

class vtkPolyData;

namespace mlr::cli
{

/// The frames of the series `collection` (PATH.pvd) are PATH_0000.vtu ... next to it; other
/// per-frame files (pictures) follow the same numbering.
struct SeriesNaming
{
  std::filesystem::path directory;
  std::string stem;
  int digits = 4;

  SeriesNaming(const std::filesystem::path& collection, std::size_t frames);
  std::string framePrefix() const { return this->stem + "_"; }
  std::string frameName(std::size_t frame, const std::string& extension) const;
};

/// Writes one frame (the filter's Elements output) as an unstructured grid of triangles with
/// its cell and field data and a field array TimeValue. Throws std::runtime_error.
void writeFrame(vtkPolyData* elements, double time, const std::filesystem::path& path);

/// Writes the .pvd collection: (time, file name relative to the .pvd) per frame.
void writeCollection(const std::filesystem::path& path,
  const std::vector<std::pair<double, std::string>>& frames);

} // namespace mlr::cli
