// Reading the scene, light and trajectory files (through the guarded reading of
// GuardedRead/), or the Cornell box compiled into the program.
#pragma once

#include "GuardedRead.h"

#include "vtkSmartPointer.h"

#include <cstdint>
#include <string>

class vtkPolyData;

namespace mlr::cli
{

/// An input that cannot be used: the message names the file and the problem.
using InputError = mlr::guarded::InputError;

/**
 * Reads a .vtp .vtu .vtk .obj .ply or .stl file as polygons with mlr::guarded::readSurfaceFile:
 * checked first, then read in a child process whose address space may grow by
 * `memoryLimitBytes` (0: half the physical memory) and whose time is limited to 5 s of CPU
 * time plus 1 s per MiB of file (4 times that of wall-clock time). `role` ("scene", "light",
 * ...) names it in messages. Throws InputError.
 */
vtkSmartPointer<vtkPolyData> readSurfaceFile(
  const std::string& path, const std::string& role, std::uint64_t memoryLimitBytes = 0);

/**
 * The scene file: as readSurfaceFile, but the files vtkRadiositySceneReader reads (.obj with
 * its .mtl, .gltf, .glb, .ply: its GetFileExtensions()) are read with their materials by it
 * (cell arrays Reflectance, Emission, MaterialId, field data MaterialNames), in the same
 * guarded reading process.
 */
vtkSmartPointer<vtkPolyData> readSceneFile(
  const std::string& path, std::uint64_t memoryLimitBytes = 0);

/// A .vtp file of Data/ compiled into the program (cornell_box.vtp, cornell_light.vtp,
/// cornell_trajectory.vtp).
vtkSmartPointer<vtkPolyData> readEmbeddedFile(const std::string& name);

} // namespace mlr::cli
