#include "InputFiles.h"

#include "EmbeddedData.h"

#include "vtkNew.h"
#include "vtkPolyData.h"
#include "vtkXMLPolyDataReader.h"

namespace mlr::cli
{

vtkSmartPointer<vtkPolyData> readSurfaceFile(
  const std::string& path, const std::string& role, std::uint64_t memoryLimitBytes)
{
  mlr::guarded::ReadLimits limits;
  limits.memoryBytes = memoryLimitBytes;
  try
  {
    return mlr::guarded::readSurfaceFile(path, role, limits);
  }
  catch (const mlr::guarded::ReadInterrupted& interrupted)
  {
    // Every input is read before anything is written.
    throw InputError(std::string(interrupted.what()) + ": nothing was written");
  }
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
