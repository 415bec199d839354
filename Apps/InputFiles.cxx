#include "InputFiles.h"

#include "EmbeddedData.h"
#include "Messages.h"

#include "vtkDataSet.h"
#include "vtkGenericDataObjectReader.h"
#include "vtkGeometryFilter.h"
#include "vtkNew.h"
#include "vtkOBJReader.h"
#include "vtkPLYReader.h"
#include "vtkPolyData.h"
#include "vtkSTLReader.h"
#include "vtkXMLPolyDataReader.h"
#include "vtkXMLUnstructuredGridReader.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

namespace mlr::cli
{

namespace
{
std::string extensionOf(const std::string& path)
{
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

/// Runs `reader` and returns its output as polygons; null if VTK reported an error.
vtkSmartPointer<vtkPolyData> runReader(vtkAlgorithm* reader)
{
  const std::size_t errorsBefore = vtkErrorCount();
  reader->Update();
  vtkDataObject* output = reader->GetOutputDataObject(0);
  if (vtkErrorCount() != errorsBefore || reader->GetErrorCode() != 0 || !output)
  {
    return nullptr;
  }
  if (auto* polygons = vtkPolyData::SafeDownCast(output))
  {
    return polygons;
  }
  if (!vtkDataSet::SafeDownCast(output))
  {
    return nullptr;
  }
  // Volumetric or other data sets: their surface, with the cell arrays carried along.
  vtkNew<vtkGeometryFilter> surface;
  surface->SetInputData(output);
  surface->Update();
  return vtkErrorCount() == errorsBefore ? surface->GetOutput() : nullptr;
}
}

vtkSmartPointer<vtkPolyData> readSurfaceFile(const std::string& path, const std::string& role)
{
  const std::string what = "the " + role + " file '" + path + "'";
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error))
  {
    throw InputError(what + " does not exist or is not a file");
  }
  if (!std::ifstream(path).good())
  {
    throw InputError(what + " cannot be opened: check its permissions");
  }

  const std::string extension = extensionOf(path);
  vtkSmartPointer<vtkAlgorithm> reader;
  if (extension == ".vtp" || extension == ".vtu")
  {
    vtkSmartPointer<vtkXMLReader> xml;
    if (extension == ".vtp")
    {
      xml = vtkSmartPointer<vtkXMLPolyDataReader>::New();
    }
    else
    {
      xml = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
    }
    if (!xml->CanReadFile(path.c_str()))
    {
      throw InputError(what + " is not a VTK XML " +
        (extension == ".vtp" ? "PolyData" : "UnstructuredGrid") + " file");
    }
    xml->SetFileName(path.c_str());
    reader = xml;
  }
  else if (extension == ".vtk")
  {
    auto legacy = vtkSmartPointer<vtkGenericDataObjectReader>::New();
    legacy->SetFileName(path.c_str());
    reader = legacy;
  }
  else if (extension == ".obj")
  {
    auto obj = vtkSmartPointer<vtkOBJReader>::New();
    obj->SetFileName(path.c_str());
    reader = obj;
  }
  else if (extension == ".ply")
  {
    auto ply = vtkSmartPointer<vtkPLYReader>::New();
    ply->SetFileName(path.c_str());
    reader = ply;
  }
  else if (extension == ".stl")
  {
    auto stl = vtkSmartPointer<vtkSTLReader>::New();
    stl->SetFileName(path.c_str());
    reader = stl;
  }
  else
  {
    throw InputError(what + " has an unknown extension: give a .vtp .vtu .vtk .obj .ply or .stl file");
  }

  vtkSmartPointer<vtkPolyData> data = runReader(reader);
  if (!data)
  {
    throw InputError("cannot read " + what + " (see the messages above)");
  }
  if (data->GetNumberOfPoints() == 0)
  {
    throw InputError(what + " has no points");
  }
  return data;
}

vtkSmartPointer<vtkPolyData> readEmbeddedFile(const std::string& name)
{
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->ReadFromInputStringOn();
  reader->SetInputString(embeddedDataFile(name));
  vtkSmartPointer<vtkPolyData> data = runReader(reader);
  if (!data)
  {
    throw InputError("the built-in " + name + " is damaged: rebuild the program");
  }
  return data;
}

} // namespace mlr::cli
