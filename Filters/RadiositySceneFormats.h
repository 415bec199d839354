// The file formats vtkRadiositySceneReader reads: Wavefront OBJ with its MTL materials, glTF 2.0
// (.gltf, .glb) and PLY with colours, each into one polygon soup with a material per cell.
// Each format is read in its own file (ObjMtlFormat.cxx, GltfFormat.cxx, PlyFormat.cxx) with
// the helpers of SceneText.h and SceneTextures.h. Private to the Filters module.
#pragma once

#include "MemoryBudget.h"

#include "vtkSmartPointer.h"

#include <array>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

class vtkCellArray;
class vtkPoints;

namespace mlr::scenefile
{

/// A file that cannot be read; the message names the file and what is wrong with it.
class FileError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// Thrown when the Progress callback asks to stop.
struct Aborted
{
};

/// Receives each warning (a message naming the file), for vtkWarningMacro.
using Warn = std::function<void(const std::string&)>;

/// Receives progress in [0, 1] and returns true to go on, false to stop (abort).
using Progress = std::function<bool(double)>;

/// The grey that stands in for a material the files do not describe.
constexpr double FallbackReflectance = 0.5;
/// The largest reflectance kept: a surface reflecting all light it receives makes a closed
/// scene's radiosity diverge, and modelling tools often export Kd 1 1 1.
constexpr double MaxReflectance = 0.99;

struct Material
{
  std::string name;
  /// Diffuse reflectance, each component in [0, MaxReflectance].
  std::array<double, 3> reflectance{ { FallbackReflectance, FallbackReflectance,
    FallbackReflectance } };
  /// Emitted radiance, W/(m^2 sr): MTL Ke or glTF emissiveFactor x emissive strength.
  std::array<double, 3> radiance{ { 0, 0, 0 } };
};

/// A scene read from a file: polygons, a material per cell, and for formats that colour each
/// cell (PLY, glTF COLOR_0) a reflectance per cell that replaces the material's.
struct Scene
{
  vtkSmartPointer<vtkPoints> points;
  vtkSmartPointer<vtkCellArray> polygons;
  std::vector<int> materialOfCell;
  std::vector<Material> materials;
  std::vector<std::array<double, 3>> cellReflectance; ///< empty, or one per cell
  std::string format;                                 ///< "OBJ", "glTF" or "PLY"
};

/// Kd-like components clamped into [0, MaxReflectance]: a warning names `what` when a value
/// reaches 1; FileError when a value is negative or not a number.
std::array<double, 3> checkedReflectance(
  std::array<double, 3> rgb, const std::string& what, const Warn& warn);

/// Wavefront OBJ and the MTL files its mtllib lines name (relative to the OBJ's folder).
/// Kd becomes the reflectance, Ke the radiance; map_Kd and map_Ke multiply them by the mean
/// linear colour of their PNG or JPEG texture (map_Kd without Kd: the mean alone), and a
/// texture that cannot be read or decoded is a warning. A missing MTL file or material falls back
/// to grey FallbackReflectance with a warning naming it. Points (p) and lines (l) are skipped with
/// a warning. FileError when the file cannot be read, is malformed, or has no faces.
Scene readObj(
  const std::string& path, const Warn& warn, const Progress& progress, const MemoryBudget& budget);

/// glTF 2.0, .gltf (JSON, buffers embedded as data: URIs or in files beside it) or .glb, with
/// every index and accessor checked against the file before use. The default scene's meshes
/// with their node transforms, in metres; triangles, strips and fans (points and lines are
/// skipped with a warning). Material: baseColorFactor times the mean of
/// its base colour texture (linear) is the reflectance, emissiveFactor times
/// KHR_materials_emissive_strength times the mean of its emissive texture the radiance.
/// COLOR_0 multiplies the reflectance per cell (mean over the cell's vertices). FileError
/// when the file cannot be read, is malformed, or has no triangles.
Scene readGltf(
  const std::string& path, const Warn& warn, const Progress& progress, const MemoryBudget& budget);

/// PLY (ASCII or binary), element vertex (x, y, z, optional red/green/blue or
/// diffuse_red/...), element face (vertex_indices or vertex_index, optional red/green/blue)
/// and element tristrips (the same list, -1 ending a strip; every other triangle turned,
/// those of repeated indices dropped).
/// Colours: 8-bit integers /255, 16-bit /65535, float and double as they are. A face colour
/// is the cell's reflectance, else the mean of its vertices' colours, else grey with a
/// warning. One material named after the file. FileError when the file cannot be read, is
/// malformed, or has no faces.
Scene readPly(
  const std::string& path, const Warn& warn, const Progress& progress, const MemoryBudget& budget);

/// The output's estimated bytes for `points` points and `triangles` triangles (coordinates,
/// connectivity and the per-cell arrays), checked against `budget` before reading them:
/// FileError naming `path` and the estimate when it does not fit. `fromFileSize`: the counts
/// are bounds from the file's size, and the message says so.
void checkOutputSize(const std::string& path, const std::string& format, std::uint64_t points,
  std::uint64_t triangles, const MemoryBudget& budget, bool fromFileSize = false);

} // namespace mlr::scenefile
