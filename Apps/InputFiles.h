// Reading the scene, light and trajectory files, or the Cornell box compiled into the program.
#pragma once

#include "vtkSmartPointer.h"

#include <cstdint>
#include <stdexcept>
#include <string>

class vtkPolyData;

namespace mlr::cli
{

/// An input that cannot be used: the message names the file and the problem.
class InputError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/**
 * Reads a .vtp .vtu .vtk .obj .ply or .stl file as polygons (the surface of volumetric data),
 * keeping its cell arrays. `role` ("scene", "light", ...) names it in messages. Throws
 * InputError when the file is missing, unreadable or has no points.
 *
 * VTK's readers are not hardened against damaged files (fuzzing crashed several of them), so
 * the file is first checked (FileChecks.h) and then read in a child process, whose address
 * space is limited to `memoryLimitBytes` (0: half the physical memory) more than it starts
 * with; a child that crashes or runs out of memory costs only that file, with a message. The
 * child hands its result back as VTK XML in memory.
 */
vtkSmartPointer<vtkPolyData> readSurfaceFile(
  const std::string& path, const std::string& role, std::uint64_t memoryLimitBytes = 0);

/// A .vtp file of Data/ compiled into the program (cornell_box.vtp, cornell_light.vtp,
/// cornell_trajectory.vtp).
vtkSmartPointer<vtkPolyData> readEmbeddedFile(const std::string& name);

} // namespace mlr::cli
