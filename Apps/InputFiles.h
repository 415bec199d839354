// Reading the scene, light and trajectory files, or the Cornell box compiled into the program.
#pragma once

#include "vtkSmartPointer.h"

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

/// Reads a .vtp .vtu .vtk .obj .ply or .stl file as polygons (the surface of volumetric data),
/// keeping its cell arrays. `role` ("scene", "light", ...) names it in messages. Throws
/// InputError when the file is missing, unreadable or has no points.
vtkSmartPointer<vtkPolyData> readSurfaceFile(const std::string& path, const std::string& role);

/// A .vtp file of Data/ compiled into the program (cornell_box.vtp, cornell_light.vtp,
/// cornell_trajectory.vtp).
vtkSmartPointer<vtkPolyData> readEmbeddedFile(const std::string& name);

} // namespace mlr::cli
