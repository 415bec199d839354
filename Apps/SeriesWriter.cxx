#include "SeriesWriter.h"

#include "OutputTransaction.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCellType.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"
#include "vtkXMLUnstructuredGridWriter.h"
#include "vtkXMLWriter.h"

#include <algorithm>
#include <cmath>
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

std::filesystem::path sensorsCollectionOf(const std::filesystem::path& collection)
{
  return collection.parent_path() / (collection.stem().string() + "_sensors.pvd");
}

std::string SeriesNaming::frameName(std::size_t frame, const std::string& extension) const
{
  std::ostringstream name;
  name << this->framePrefix() << std::setw(this->digits) << std::setfill('0') << frame << extension;
  return name.str();
}

namespace
{
/// The XML writer writes the value range of every array (RangeMin, RangeMax: the range of a
/// single component, else of the tuples' norms), which VTK computes at about 20 ns a value and
/// caches in the array's information object: for the arrays of a frame, that took longer than
/// compressing and writing them. Here the same ranges are computed in one pass over AOS arrays
/// and cached under VTK's keys, which VTK uses while the array is not modified afterwards.
template <typename T>
bool cacheRangeOf(vtkDataArray* array)
{
  auto* typed = vtkAOSDataArrayTemplate<T>::FastDownCast(array);
  if (!typed)
  {
    return false;
  }
  const int components = typed->GetNumberOfComponents();
  const vtkIdType tuples = typed->GetNumberOfTuples();
  const T* values = typed->GetPointer(0);
  double range[2] = { std::numeric_limits<double>::infinity(),
    -std::numeric_limits<double>::infinity() };
  double norms[2] = { range[0], range[1] }; // squared
  for (vtkIdType t = 0; t < tuples; ++t)
  {
    const T* tuple = values + t * components;
    double squared = 0;
    for (int c = 0; c < components; ++c)
    {
      const double v = static_cast<double>(tuple[c]);
      squared += v * v;
    }
    if (std::isnan(squared))
    {
      continue; // VTK's ranges skip NaN too
    }
    norms[0] = std::min(norms[0], squared);
    norms[1] = std::max(norms[1], squared);
    if (components == 1)
    {
      range[0] = std::min(range[0], static_cast<double>(tuple[0]));
      range[1] = std::max(range[1], static_cast<double>(tuple[0]));
    }
  }
  if (!(norms[0] <= norms[1]))
  {
    return false; // empty or all NaN: left to VTK
  }
  vtkInformation* info = typed->GetInformation();
  const double l2[2] = { std::sqrt(norms[0]), std::sqrt(norms[1]) };
  info->Set(vtkDataArray::L2_NORM_RANGE(), l2, 2);
  if (components == 1)
  {
    vtkNew<vtkInformationVector> perComponent;
    perComponent->SetNumberOfInformationObjects(1);
    perComponent->GetInformationObject(0)->Set(vtkDataArray::COMPONENT_RANGE(), range, 2);
    info->Set(vtkDataArray::PER_COMPONENT(), perComponent);
  }
  return true;
}

/// Caches the range the XML writer asks for. Called on the converting thread only, and only
/// once for an array that frames share, so that the writing threads only read the cache.
void cacheRange(vtkDataArray* array)
{
  if (!array)
  {
    return;
  }
  const int component = array->GetNumberOfComponents() == 1 ? 0 : -1;
  vtkInformation* info = array->HasInformation() ? array->GetInformation() : nullptr;
  const bool cached = info &&
    (component < 0 ? info->Has(vtkDataArray::L2_NORM_RANGE())
                   : info->Has(vtkDataArray::PER_COMPONENT()));
  if (!cached)
  {
    cacheRangeOf<float>(array) || cacheRangeOf<double>(array) || cacheRangeOf<int>(array) ||
      cacheRangeOf<long long>(array) || cacheRangeOf<long>(array) ||
      cacheRangeOf<unsigned char>(array);
  }
  // VTK's own look-up: computes the range here if the cache above does not serve.
  double range[2];
  array->GetRange(range, component);
}

void cacheRanges(vtkFieldData* data)
{
  for (int i = 0; data && i < data->GetNumberOfArrays(); ++i)
  {
    cacheRange(data->GetArray(i));
  }
}

}

FrameWriter::FrameWriter(unsigned threads)
  : MaxQueued(2 * std::max(threads, 1u))
{
  for (unsigned i = 0; i < std::max(threads, 1u); ++i)
  {
    this->Threads.emplace_back([this] { this->work(); });
  }
}

FrameWriter::~FrameWriter()
{
  this->stop();
}

void FrameWriter::stop() noexcept
{
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    this->Stopping = true;
    this->Queue.clear();
  }
  this->Changed.notify_all();
  for (std::thread& thread : this->Threads)
  {
    if (thread.joinable())
    {
      thread.join();
    }
  }
}

void FrameWriter::write(vtkPolyData* elements, double time, const std::filesystem::path& path)
{
  // The element mesh is all triangles, and the same in every frame: its points, cells and
  // cell types are converted once and shared.
  if (elements->GetPoints() != this->Points || elements->GetPolys() != this->Polys ||
    !this->CellTypes || this->CellTypes->GetNumberOfTuples() != elements->GetNumberOfPolys())
  {
    this->Points = elements->GetPoints();
    this->Polys = elements->GetPolys();
    this->CellTypes = vtkSmartPointer<vtkUnsignedCharArray>::New();
    this->CellTypes->SetNumberOfTuples(elements->GetNumberOfPolys());
    this->CellTypes->FillValue(VTK_TRIANGLE);
    cacheRange(this->Points ? this->Points->GetData() : nullptr);
    cacheRange(this->Polys ? this->Polys->GetConnectivityArray() : nullptr);
    cacheRange(this->Polys ? this->Polys->GetOffsetsArray() : nullptr);
    cacheRange(this->CellTypes);
  }
  Job job{ this->Points, this->Polys, this->CellTypes, vtkSmartPointer<vtkPointData>::New(),
    vtkSmartPointer<vtkCellData>::New(), vtkSmartPointer<vtkFieldData>::New(), path };
  job.pointData->ShallowCopy(elements->GetPointData());
  job.cellData->ShallowCopy(elements->GetCellData());
  job.fieldData->ShallowCopy(elements->GetFieldData());
  keepOwnFrameFigures(job.fieldData);
  vtkNew<vtkDoubleArray> timeValue;
  timeValue->SetName("TimeValue");
  timeValue->InsertNextValue(time);
  job.fieldData->AddArray(timeValue);
  cacheRanges(job.pointData);
  cacheRanges(job.cellData);
  cacheRanges(job.fieldData);

  std::unique_lock<std::mutex> lock(this->Mutex);
  // Bounded: frames are produced faster than written on a slow disk.
  this->Changed.wait(
    lock, [this] { return this->Queue.size() < this->MaxQueued || this->Failure; });
  if (this->Failure)
  {
    std::rethrow_exception(this->Failure);
  }
  this->Queue.push_back(std::move(job));
  lock.unlock();
  this->Changed.notify_all();
}

void FrameWriter::finish()
{
  std::unique_lock<std::mutex> lock(this->Mutex);
  this->Changed.wait(
    lock, [this] { return (this->Queue.empty() && this->Busy == 0) || this->Failure; });
  if (this->Failure)
  {
    std::rethrow_exception(this->Failure);
  }
}

void FrameWriter::work()
{
  // Kept from frame to frame: VTK caches what it derives from the mesh (the distinct cell
  // types, which the writer asks for) in the grid, and that cache holds while only the cell
  // and field data change. Both are created and destroyed on this thread.
  vtkNew<vtkUnstructuredGrid> grid;
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  writer->SetInputData(grid);
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetCompressorTypeToLZ4();
  std::unique_lock<std::mutex> lock(this->Mutex);
  for (;;)
  {
    this->Changed.wait(lock, [this] { return this->Stopping || !this->Queue.empty(); });
    if (this->Stopping)
    {
      return;
    }
    Job job = std::move(this->Queue.front());
    this->Queue.pop_front();
    ++this->Busy;
    lock.unlock();
    std::exception_ptr failure;
    try
    {
      if (grid->GetPoints() != job.points || grid->GetCells() != job.polys)
      {
        grid->SetPoints(job.points);
        grid->SetCells(job.cellTypes, job.polys);
      }
      grid->GetPointData()->ShallowCopy(job.pointData);
      grid->GetCellData()->ShallowCopy(job.cellData);
      grid->GetFieldData()->ShallowCopy(job.fieldData);
      writeXml(writer, job.path, "the frame");
    }
    catch (...)
    {
      failure = std::current_exception();
    }
    job = Job(); // released here, not under the lock
    lock.lock();
    --this->Busy;
    if (failure && !this->Failure)
    {
      this->Failure = failure;
    }
    this->Changed.notify_all();
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
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      default:
        escaped += c;
    }
  }
  return escaped;
}
}

void failedWrite(const std::string& what, const std::filesystem::path& path)
{
  std::string name = OutputTransaction::shownNameOf(path.filename().string());
  if (name.empty())
  {
    name = path.filename().string();
  }
  throw std::runtime_error("cannot write " + what + " '" + (path.parent_path() / name).string() +
    "': check the disk space and the permissions of its directory");
}

void writeFileBytes(
  const std::filesystem::path& path, const std::string& bytes, const std::string& what)
{
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out)
  {
    failedWrite(what, path);
  }
}

namespace
{
/// A file buffer whose writes always succeed as far as its stream can tell: the first that
/// fails is recorded, and the rest are dropped.
class RecordingFileBuf : public std::filebuf
{
public:
  bool failed() const { return this->Failed; }

protected:
  int_type overflow(int_type c) override
  {
    if (!this->Failed && traits_type::eq_int_type(std::filebuf::overflow(c), traits_type::eof()) &&
      !traits_type::eq_int_type(c, traits_type::eof()))
    {
      this->Failed = true;
    }
    if (this->Failed)
    {
      this->setp(this->pbase(), this->epptr());
    }
    return traits_type::not_eof(c);
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override
  {
    if (!this->Failed && std::filebuf::xsputn(s, n) < n)
    {
      this->Failed = true;
    }
    return n;
  }
  int sync() override
  {
    if (!this->Failed && std::filebuf::sync() != 0)
    {
      this->Failed = true;
    }
    return 0;
  }
  pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode which) override
  {
    const pos_type at =
      this->Failed ? pos_type(off_type(-1)) : std::filebuf::seekoff(off, dir, which);
    this->Failed = this->Failed || at == pos_type(off_type(-1));
    return this->Failed ? pos_type(off_type(0)) : at;
  }
  pos_type seekpos(pos_type to, std::ios_base::openmode which) override
  {
    const pos_type at = this->Failed ? pos_type(off_type(-1)) : std::filebuf::seekpos(to, which);
    this->Failed = this->Failed || at == pos_type(off_type(-1));
    return this->Failed ? to : at;
  }

private:
  bool Failed = false;
};

/// The writer's output stream, which it otherwise opens on its file name itself.
struct StreamOf : vtkXMLWriter
{
  static std::ostream* vtkXMLWriter::*member() { return &StreamOf::Stream; }
};
}

void writeXml(vtkXMLWriter* writer, const std::filesystem::path& path, const std::string& what)
{
  RecordingFileBuf file;
  bool written = file.open(path, std::ios::out | std::ios::binary | std::ios::trunc) != nullptr;
  if (written)
  {
    std::ostream stream(&file);
    writer->*StreamOf::member() = &stream;
    written = writer->Write() && writer->GetErrorCode() == 0;
    writer->*StreamOf::member() = nullptr;
    stream.flush();
    written = file.close() != nullptr && written && !file.failed();
  }
  if (!written)
  {
    failedWrite(what, path);
  }
}

void keepOwnFrameFigures(vtkFieldData* fieldData)
{
  vtkDataArray* shown = fieldData->GetArray("FrameIndex");
  if (!shown || shown->GetNumberOfTuples() == 0)
  {
    return;
  }
  const auto frame = static_cast<vtkIdType>(shown->GetComponent(0, 0));
  for (const char* name : { "RelativeErrorMedian", "RelativeErrorP95", "LitElements",
         "SensorRelativeErrorMedian", "SensorRelativeErrorP95", "LitSensors" })
  {
    vtkDataArray* all = fieldData->GetArray(name);
    if (!all || all->GetNumberOfTuples() == 0)
    {
      continue;
    }
    vtkSmartPointer<vtkDataArray> own;
    own.TakeReference(all->NewInstance());
    own->SetName(name);
    own->SetNumberOfComponents(all->GetNumberOfComponents());
    // A scene lit only by what does not move is one frame shown at every time step.
    own->InsertNextTuple(std::clamp<vtkIdType>(frame, 0, all->GetNumberOfTuples() - 1), all);
    fieldData->AddArray(own); // replaces the array of that name
  }
}

void writeCollection(
  const std::filesystem::path& path, const std::vector<std::pair<double, std::string>>& frames)
{
  std::ofstream out(path);
  out << std::setprecision(std::numeric_limits<double>::max_digits10);
  out << "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         "  <Collection>\n";
  for (const auto& [time, file] : frames)
  {
    out << "    <DataSet timestep=\"" << time << "\" group=\"\" part=\"0\" file=\""
        << xmlEscaped(file) << "\"/>\n";
  }
  out << "  </Collection>\n</VTKFile>\n";
  out.close();
  if (!out)
  {
    failedWrite("the collection", path);
  }
}

} // namespace mlr::cli
