// The .pvd + .vtu time series: file names, frames and the collection file.
#pragma once

#include "vtkSmartPointer.h"

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

class vtkCellArray;
class vtkCellData;
class vtkFieldData;
class vtkPointData;
class vtkPoints;
class vtkPolyData;
class vtkUnsignedCharArray;
class vtkXMLWriter;

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

/// The sensors' series beside the series `collection` (PATH.pvd): PATH_sensors.pvd, whose
/// frames are PATH_sensors_0000.vtp ...
std::filesystem::path sensorsCollectionOf(const std::filesystem::path& collection);

/**
 * Writes the frames of a series, each the filter's Elements output as an unstructured grid of
 * triangles with its cell, point and field data and a field array TimeValue, LZ4-compressed
 * (VTK's vtkLZ4DataCompressor, which ParaView and VTK's readers read; zlib took as long as the
 * solve). The calling thread takes each frame's point, cell and field data; background
 * threads, each with one unstructured grid of the element mesh's points and cells (converted
 * once while the filter hands out the same mesh), swap them in, compress and write the frame
 * meanwhile, so that writing overlaps the next frame's update.
 */
class FrameWriter
{
public:
  /// `threads` background writers (at least 1); at most twice that many frames wait in memory.
  explicit FrameWriter(unsigned threads = 1);
  /// Waits for the frames being written (their files are the caller's to remove).
  ~FrameWriter();
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;

  /// Converts `elements` now and writes it to `path` in the background. Throws the
  /// std::runtime_error of an earlier frame that could not be written.
  void write(vtkPolyData* elements, double time, const std::filesystem::path& path);

  /// Waits until every frame is written; throws std::runtime_error if one could not be.
  void finish();

private:
  /// One frame: the shared mesh and the frame's own point, cell and field data.
  struct Job
  {
    vtkSmartPointer<vtkPoints> points;
    vtkSmartPointer<vtkCellArray> polys;
    vtkSmartPointer<vtkUnsignedCharArray> cellTypes;
    vtkSmartPointer<vtkPointData> pointData;
    vtkSmartPointer<vtkCellData> cellData;
    vtkSmartPointer<vtkFieldData> fieldData;
    std::filesystem::path path;
  };
  void work();
  void stop() noexcept;

  // The geometry of the last frame, shared by the next ones while the filter hands out the
  // same points and cells.
  vtkSmartPointer<vtkPoints> Points;
  vtkSmartPointer<vtkCellArray> Polys;
  vtkSmartPointer<vtkUnsignedCharArray> CellTypes;

  std::mutex Mutex;
  std::condition_variable Changed;
  std::deque<Job> Queue;
  std::size_t Busy = 0;
  std::size_t MaxQueued = 2;
  bool Stopping = false;
  std::exception_ptr Failure;
  std::vector<std::thread> Threads;
};

/**
 * Writes `bytes` to `path` (created or truncated), or throws naming `what` and the path when
 * any of them cannot be written (a picture encoded in memory).
 */
void writeFileBytes(
  const std::filesystem::path& path, const std::string& bytes, const std::string& what);

/**
 * Writes `path` (created or truncated) with `writer`, an XML writer whose input is set, or
 * throws naming `what` and the path when any of it cannot be written. The writer streams into
 * a file buffer that records a failed write instead of reporting it: VTK 9.2's XML writers
 * crash in their own error path on a full disk, and encoding in memory first would hold whole
 * frames per writing thread.
 */
void writeXml(vtkXMLWriter* writer, const std::filesystem::path& path, const std::string& what);

/**
 * Replaces in `fieldData` each of the filter's arrays of one figure per frame (the error
 * estimate's RelativeErrorMedian, RelativeErrorP95, LitElements and the sensors' own) by
 * the figure of the frame it shows (its FrameIndex): a frame's file holds its own, not a
 * year's worth in every file. The arrays replaced are new: the filter's stay whole.
 */
void keepOwnFrameFigures(vtkFieldData* fieldData);

/// Writes the .pvd collection: (time, file name relative to the .pvd) per frame.
void writeCollection(
  const std::filesystem::path& path, const std::vector<std::pair<double, std::string>>& frames);

/// Throws that `what` could not be written to `path`, named as the user asked for it: a
/// staged file's hidden temporary name (.NAME.partial) as NAME, with the disk hint.
[[noreturn]] void failedWrite(const std::string& what, const std::filesystem::path& path);

} // namespace mlr::cli
