/**
 * @class   vtkRadiositySceneReader
 * @brief   reads a scene with its materials (OBJ + MTL, glTF 2.0, PLY) for vtkMovingLightRadiosity
 *
 * vtkRadiositySceneReader reads the polygons of a scene file and gives every cell the diffuse
 * reflectance and the emission of its material, in the arrays vtkMovingLightRadiosity and the
 * command line read:
 *
 * - cell array `Reflectance` (double, 3 components, RGB, each in [0, 0.99]);
 * - cell array `Emission` (double, 3 components, W/m^2): the radiant exitance of the cell,
 *   pi times the material's emitted radiance, so that a material emits
 *   pi x radiance x area watts per colour channel; 0 for materials that do not emit;
 * - cell array `MaterialId` (int) and field data `MaterialNames` (vtkStringArray, indexed by
 *   MaterialId);
 * - field data `EmissionUnits` ("W/m^2") and `SceneFormat` ("OBJ", "glTF" or "PLY").
 *
 * Formats, chosen by the file's extension (case-insensitive):
 * - `.obj`: Wavefront OBJ faces, with the materials of the MTL files its `mtllib` lines name
 *   (relative to the OBJ's folder). `Kd` is the reflectance, `Ke` the emitted radiance in
 *   W/(m^2 sr), as path tracers read it (the Cornell box's `Ke 17 12 4` light emits
 *   pi x (17, 12, 4) W/m^2). Faces before any `usemtl` have the material `none`. The PNG or
 *   JPEG textures of `map_Kd` and `map_Ke` multiply Kd and Ke by their mean linear colour
 *   (`map_Kd` without Kd: the mean alone is the reflectance; `map_Ke` only scales a non-zero
 *   Ke); a texture that cannot be read or decoded is a warning, and the colour alone is used.
 *   Points and lines are skipped with a warning. A missing MTL file, or a material it does not
 *   define, is grey 0.5 and does not emit, with a warning naming the file or the material.
 * - `.gltf`, `.glb`: glTF 2.0 (buffers embedded, in a .glb BIN chunk or in files beside it),
 *   the default scene with its node transforms (glTF lengths are metres), skins and animations
 *   in the rest pose. Files that require geometry extensions (Draco, quantization, meshopt)
 *   are refused.
 *   Triangles, strips and fans are read; points and lines are skipped with a warning, and a
 *   file with no triangles is an error. `baseColorFactor` (RGB) times the mean linear colour of
 *   the base colour texture is the reflectance; `COLOR_0` multiplies it per cell (mean over the
 *   cell's vertices). `emissiveFactor` times `KHR_materials_emissive_strength` (1 without it)
 *   times the mean of the emissive texture is the emitted radiance in W/(m^2 sr), read like
 *   OBJ's Ke: emissiveFactor (1, 1, 1) with strength 17 emits as Ke 17 17 17. Primitives
 *   without a material have glTF's default material, `default` (white, clamped).
 * - `.ply`: faces with per-face `red`/`green`/`blue` (or per-vertex ones, averaged over each
 *   face's vertices; `diffuse_red`/... too): 8-bit values are divided by 255, 16-bit ones by
 *   65535, floats are taken as they are. No emission; one material named after the file.
 *
 * A reflectance of 1 or more (modelling tools often export Kd 1 1 1) is clamped to 0.99 with a
 * warning naming the material. Lengths are kept as the file has them.
 *
 * VTK 9.2's own readers are not used for geometry: vtkOBJReader gives the first faces after a
 * `usemtl` the material NO_MATERIAL and crashes on indices the file does not define,
 * vtkPLYReader truncates float colours to 0 and crashes on some malformed headers, and
 * vtkGLTFDocumentLoader aborts (a failed assertion in Debian's build) on a material without
 * pbrMetallicRoughness, which glTF allows, and reads accessors past their buffers. The formats
 * are read here instead (glTF's JSON with VTK's nlohmann::json, PNG textures with libpng's
 * simplified API, since vtkPNGReader crashes on damaged images, JPEG ones with vtkJPEGReader),
 * checking every index and size before using it.
 *
 * Bad input (a missing, unreadable or malformed file, an unknown extension, a file without
 * faces or triangles) gives an error naming the file and what is wrong, and an empty output.
 * Progress is reported through UpdateProgress; AbortExecute stops the reading with an empty
 * output and an error, and clears the flag. As in vtkMovingLightRadiosity, an aborted update
 * reports no progress after the abort, not even the 1.0 VTK's executive reports at the end of
 * every execution (which ParaView shows as a finished update): the progress goes through the
 * reader's own vtkProgressObserver, and a ProgressEvent past an abort is dropped. Replacing
 * that observer with SetProgressObserver replaces this too.
 *
 * @sa
 * vtkMovingLightRadiosity
 */

#ifndef vtkRadiositySceneReader_h
#define vtkRadiositySceneReader_h

#include "MovingLightRadiosityFiltersModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

class MOVINGLIGHTRADIOSITYFILTERS_EXPORT vtkRadiositySceneReader : public vtkPolyDataAlgorithm
{
public:
  static vtkRadiositySceneReader* New();
  vtkTypeMacro(vtkRadiositySceneReader, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The scene file: .obj (with its .mtl files), .gltf, .glb or .ply. Default: none (an error
   * on update).
   */
  vtkSetFilePathMacro(FileName);
  vtkGetFilePathMacro(FileName);
  ///@}

  ///@{
  /**
   * Largest memory, in MiB, the output may be estimated to need. The estimate is made from
   * the file's declared counts (glTF: every mesh instance the node hierarchy draws; PLY: the
   * header's vertex and face counts; OBJ: the file's size) before anything proportional to
   * them is allocated, and a file over the limit is an error naming the estimate. The same
   * policy as vtkMovingLightRadiosity's MemoryLimit; a negative limit is an error naming it.
   * Default: 0, half of the physical memory.
   */
  vtkSetMacro(MemoryLimit, int);
  vtkGetMacro(MemoryLimit, int);
  ///@}

  /**
   * Whether the extension of `fileName` is one this reader reads (GetFileExtensions()).
   * The file itself is not opened.
   */
  static int CanReadFile(const char* fileName);

  /**
   * The extensions this reader reads, lowercase, separated by spaces: ".obj .gltf .glb .ply"
   * (any case in a file name).
   */
  static const char* GetFileExtensions();

protected:
  vtkRadiositySceneReader();
  ~vtkRadiositySceneReader() override;

  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkRadiositySceneReader(const vtkRadiositySceneReader&) = delete;
  void operator=(const vtkRadiositySceneReader&) = delete;

  /// Every UpdateProgress ends here (the reader's vtkProgressObserver): a ProgressEvent,
  /// unless this update was aborted.
  void ReportProgress(double amount);

  char* FileName = nullptr;
  int MemoryLimit = 0;
  /// This update was aborted: nothing more is reported until the next one starts.
  bool ProgressStopped = false;
};

#endif
