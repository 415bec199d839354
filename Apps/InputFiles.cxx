#include "InputFiles.h"

#include "EmbeddedData.h"

#include "vtkNew.h"
#include "vtkPolyData.h"
#include "vtkRadiositySceneReader.h"
#include "vtkXMLPolyDataReader.h"

#include <algorithm>
#include <sstream>
#include <vector>

namespace mlr::cli
{

namespace
{
/// The extensions vtkRadiositySceneReader reads, as it lists them.
std::vector<std::string> sceneReaderExtensions()
{
  std::vector<std::string> extensions;
  std::istringstream list(vtkRadiositySceneReader::GetFileExtensions());
  for (std::string extension; list >> extension;)
  {
    extensions.push_back(extension);
  }
  return extensions;
}

vtkSmartPointer<vtkPolyData> guardedRead(const std::string& path, const std::string& role,
  std::uint64_t memoryLimitBytes, const mlr::guarded::ReaderFactory& ownReader = {},
  const std::vector<std::string>& ownExtensions = {})
{
  mlr::guarded::ReadLimits limits;
  limits.memoryBytes = memoryLimitBytes;
  try
  {
    return mlr::guarded::readSurfaceFile(path, role, limits, ownReader, ownExtensions);
  }
  catch (const mlr::guarded::ReadInterrupted& interrupted)
  {
    // Every input is read before anything is written.
    throw InputError(std::string(interrupted.what()) + ": nothing was written");
  }
}
}

vtkSmartPointer<vtkPolyData> readSurfaceFile(
  const std::string& path, const std::string& role, std::uint64_t memoryLimitBytes)
{
  return guardedRead(path, role, memoryLimitBytes);
}

vtkSmartPointer<vtkPolyData> readSceneFile(const std::string& path, std::uint64_t memoryLimitBytes)
{
  return guardedRead(
    path, "scene", memoryLimitBytes,
    [memoryLimitBytes](const std::string& file, const std::string&) -> vtkSmartPointer<vtkAlgorithm>
    {
      // Formats with materials (.obj, .gltf, .glb, .ply): our reader; VTK's for the rest.
      auto reader = vtkSmartPointer<vtkRadiositySceneReader>::New();
      reader->SetFileName(file.c_str());
      reader->SetMemoryLimit(
        static_cast<int>(std::min<std::uint64_t>(memoryLimitBytes >> 20, VTK_INT_MAX)));
      return vtkRadiositySceneReader::CanReadFile(file.c_str()) ? reader : nullptr;
    },
    sceneReaderExtensions());
}

vtkSmartPointer<vtkPolyData> readEmbeddedFile(const std::string& name)
{
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->ReadFromInputStringOn();
  reader->SetInputString(embeddedDataFile(name));
  vtkSmartPointer<vtkPolyData> data = mlr::guarded::polygonsOf(reader);
  if (!data)
  {
    throw InputError("the built-in " + name + " is damaged: rebuild the program");
  }
  return data;
}

} // namespace mlr::cli
