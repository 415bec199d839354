#include "SeriesWriter.h"

#include "vtkCellData.h"
#include "vtkCellType.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkNew.h"
#include "vtkPolyData.h"
#include "vtkUnstructuredGrid.h"
#include "vtkXMLUnstructuredGridWriter.h"

#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace mlr::cli
{

SeriesNaming::SeriesNaming(const std::filesystem::path& collection, std::size_t frames)
  : directory(collection.parent_path())
  , stem(collection.stem().string())
{
  for (std::size_t last = frames > 0 ? frames - 1 : 0; last >= 10000; last /= 10)
  {
    ++this->digits;
  }
}

std::string SeriesNaming::frameName(std::size_t frame, const std::string& extension) const
{
  std::ostringstream name;
  name << this->framePrefix() << std::setw(this->digits) << std::setfill('0') << frame
       << extension;
  return name.str();
}

void writeFrame(vtkPolyData* elements, double time, const std::filesystem::path& path)
{
  // The element mesh is all triangles: reuse its points and connectivity as they are.
  vtkNew<vtkUnstructuredGrid> grid;
  grid->SetPoints(elements->GetPoints());
  grid->SetCells(VTK_TRIANGLE, elements->GetPolys());
  grid->GetCellData()->ShallowCopy(elements->GetCellData());
  grid->GetFieldData()->ShallowCopy(elements->GetFieldData());
  vtkNew<vtkDoubleArray> timeValue;
  timeValue->SetName("TimeValue");
  timeValue->InsertNextValue(time);
  grid->GetFieldData()->AddArray(timeValue);

  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  writer->SetInputData(grid);
  writer->SetFileName(path.string().c_str());
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetCompressorTypeToZLib();
  if (!writer->Write() || writer->GetErrorCode() != 0)
  {
    throw std::runtime_error("cannot write '" + path.string() + "': check the disk space and "
                             "the permissions of its directory");
  }
}

namespace
{
std::string xmlEscaped(const std::string& text)
{
  std::string escaped;
  for (char c : text)
  {
    switch (c)
    {
      case '&': escaped += "&amp;"; break;
      case '<': escaped += "&lt;"; break;
      case '>': escaped += "&gt;"; break;
      case '"': escaped += "&quot;"; break;
      default: escaped += c;
    }
  }
  return escaped;
}
}

void writeCollection(const std::filesystem::path& path,
  const std::vector<std::pair<double, std::string>>& frames)
{
  std::ofstream out(path);
  out << std::setprecision(std::numeric_limits<double>::max_digits10);
  out << "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         "  <Collection>\n";
  for (const auto& [time, file] : frames)
  {
    out << "    <DataSet timestep=\"" << time << "\" group=\"\" part=\"0\" file=\"" << xmlEscaped(file)
        << "\"/>\n";
  }
  out << "  </Collection>\n</VTKFile>\n";
  out.close();
  if (!out)
  {
    throw std::runtime_error("cannot write '" + path.string() + "'");
  }
}

} // namespace mlr::cli
