#include "vtkRadiositySceneReader.h"

#include "ProgressForwarder.h"
#include "RadiositySceneFormats.h"

#include "MemoryBudget.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCommand.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <new>
#include <sstream>
#include <string>

vtkStandardNewMacro(vtkRadiositySceneReader);

namespace
{
std::string lowerExtension(const char* fileName)
{
  std::string extension = std::filesystem::path(fileName ? fileName : "").extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

/// A name from the file as a value of a string array: VTK's XML format ends each value with a
/// NUL byte, so a name holding one would come back as two values, and its reader then writes
/// past the array's end. Control characters become '?', which also keeps them off the screen.
std::string printableName(std::string name)
{
  std::replace_if(
    name.begin(), name.end(), [](unsigned char c) { return c < 0x20 || c == 0x7f; }, '?');
  return name;
}

vtkSmartPointer<vtkStringArray> stringField(const char* name, const std::string& value)
{
  auto array = vtkSmartPointer<vtkStringArray>::New();
  array->SetName(name);
  array->InsertNextValue(value);
  return array;
}
}

//------------------------------------------------------------------------------
vtkRadiositySceneReader::vtkRadiositySceneReader()
{
  this->SetNumberOfInputPorts(0);
  vtkNew<mlr::ProgressForwarder> progress;
  progress->Report = [this](double amount) { this->ReportProgress(amount); };
  this->SetProgressObserver(progress);
}

//------------------------------------------------------------------------------
void vtkRadiositySceneReader::ReportProgress(double amount)
{
  // Nothing past an abort: neither the reading's last reports nor the executive's 1.0.
  if (this->ProgressStopped || this->AbortExecute)
  {
    return;
  }
  this->Progress = amount;
  this->InvokeEvent(vtkCommand::ProgressEvent, &amount);
}

//------------------------------------------------------------------------------
vtkRadiositySceneReader::~vtkRadiositySceneReader()
{
  this->SetFileName(nullptr);
}

//------------------------------------------------------------------------------
int vtkRadiositySceneReader::CanReadFile(const char* fileName)
{
  const std::string extension = lowerExtension(fileName);
  std::istringstream extensions(GetFileExtensions());
  for (std::string known; extensions >> known;)
  {
    if (extension == known)
    {
      return 1;
    }
  }
  return 0;
}

//------------------------------------------------------------------------------
const char* vtkRadiositySceneReader::GetFileExtensions()
{
  return ".obj .gltf .glb .ply";
}

//------------------------------------------------------------------------------
int vtkRadiositySceneReader::RequestUpdateExtent(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // The executive asks for the update extent before every execution, and before its progress
  // of 0: an abort silences the update it stopped, not the next one.
  this->ProgressStopped = false;
  return this->Superclass::RequestUpdateExtent(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------
int vtkRadiositySceneReader::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  output->Initialize();
  if (!this->FileName || !*this->FileName)
  {
    vtkErrorMacro(<< "no FileName: give an .obj, .gltf, .glb or .ply scene file");
    return 0;
  }
  if (this->MemoryLimit < 0)
  {
    vtkErrorMacro(<< "MemoryLimit is " << this->MemoryLimit
                  << ": give 0 (half of the physical memory) or a limit in MiB");
    return 0;
  }
  const std::string path = this->FileName;
  const std::string extension = lowerExtension(this->FileName);

  namespace sf = mlr::scenefile;
  const sf::Warn warn = [this](const std::string& message) { vtkWarningMacro(<< message); };
  const sf::Progress progress = [this](double fraction)
  {
    this->UpdateProgress(0.9 * fraction);
    return !this->CheckAbort();
  };
  const mlr::MemoryBudget budget(static_cast<std::uint64_t>(this->MemoryLimit) << 20);
  sf::Scene scene;
  try
  {
    if (extension == ".obj")
    {
      scene = sf::readObj(path, warn, progress, budget);
    }
    else if (extension == ".gltf" || extension == ".glb")
    {
      scene = sf::readGltf(path, warn, progress, budget);
    }
    else if (extension == ".ply")
    {
      scene = sf::readPly(path, warn, progress, budget);
    }
    else
    {
      vtkErrorMacro(<< "the scene file '" << path << "' has the extension '" << extension
                    << "', which this reader does not read: give an .obj (with its .mtl), "
                       ".gltf, .glb or .ply file");
      return 0;
    }
  }
  catch (const sf::FileError& e)
  {
    vtkErrorMacro(<< e.what());
    return 0;
  }
  catch (const sf::Aborted&)
  {
    // The flag that stopped this update would stop the next one at once (see
    // vtkAlgorithm::CheckAbort), and this VTK's executive does not clear it: an update after
    // an abort reads again, and one aborted before it starts stops.
    this->AbortExecute = 0;
    this->ProgressStopped = true;
    vtkErrorMacro(<< "reading '" << path << "' was aborted");
    return 0;
  }
  catch (const std::bad_alloc&)
  {
    vtkErrorMacro(<< "out of memory reading the scene file '" << path << "'");
    return 0;
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro(<< "the scene file '" << path << "' could not be read: " << e.what());
    return 0;
  }

  for (const auto& material : scene.materials)
  {
    for (const double radiance : material.radiance)
    {
      if (!std::isfinite(vtkMath::Pi() * radiance))
      {
        vtkErrorMacro(<< "the material '" << material.name << "' of '" << path
                      << "' has an emission too large to represent (" << radiance
                      << " per steradian): give its Ke or emissive factor in W/sr/m^2, "
                         "below 1e300");
        return 0;
      }
    }
  }
  const vtkIdType cells = scene.polygons->GetNumberOfCells();
  vtkNew<vtkDoubleArray> reflectance;
  reflectance->SetName("Reflectance");
  reflectance->SetNumberOfComponents(3);
  reflectance->SetNumberOfTuples(cells);
  vtkNew<vtkDoubleArray> emission;
  emission->SetName("Emission");
  emission->SetNumberOfComponents(3);
  emission->SetNumberOfTuples(cells);
  vtkNew<vtkIntArray> materialId;
  materialId->SetName("MaterialId");
  materialId->SetNumberOfTuples(cells);
  for (vtkIdType cell = 0; cell < cells; ++cell)
  {
    const int id = scene.materialOfCell[static_cast<std::size_t>(cell)];
    const sf::Material& material = scene.materials[static_cast<std::size_t>(id)];
    const auto& rho = scene.cellReflectance.empty()
      ? material.reflectance
      : scene.cellReflectance[static_cast<std::size_t>(cell)];
    reflectance->SetTuple3(cell, rho[0], rho[1], rho[2]);
    // Radiance L of a diffuse emitter leaves as exitance pi x L.
    emission->SetTuple3(cell, vtkMath::Pi() * material.radiance[0],
      vtkMath::Pi() * material.radiance[1], vtkMath::Pi() * material.radiance[2]);
    materialId->SetValue(cell, id);
  }
  vtkNew<vtkStringArray> names;
  names->SetName("MaterialNames");
  for (const auto& material : scene.materials)
  {
    names->InsertNextValue(printableName(material.name));
  }

  output->SetPoints(scene.points);
  output->SetPolys(scene.polygons);
  output->GetCellData()->AddArray(reflectance);
  output->GetCellData()->AddArray(emission);
  output->GetCellData()->AddArray(materialId);
  output->GetCellData()->SetActiveScalars("Reflectance");
  output->GetFieldData()->AddArray(names);
  output->GetFieldData()->AddArray(stringField("EmissionUnits", "W/m^2"));
  output->GetFieldData()->AddArray(stringField("SceneFormat", scene.format));
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
void vtkRadiositySceneReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "MemoryLimit: " << this->MemoryLimit << " MiB (0: half of physical memory)\n";
  os << indent << "Progress reports: " << (this->ProgressStopped ? "stopped by an abort" : "on")
     << "\n";
}
