#include "GuardedRead.h"

#include "FileChecks.h"
#include "MemoryBudget.h"

#include "vtkCellArray.h"
#include "vtkDataSet.h"
#include "vtkFieldData.h"
#include "vtkGenericDataObjectReader.h"
#include "vtkGeometryFilter.h"
#include "vtkLogger.h"
#include "vtkNew.h"
#include "vtkOBJReader.h"
#include "vtkObjectFactory.h"
#include "vtkOutputWindow.h"
#include "vtkPLYReader.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPolyData.h"
#include "vtkSTLReader.h"
#include "vtkUnstructuredGrid.h"
#include "vtkXMLPolyDataReader.h"
#include "vtkXMLPolyDataWriter.h"
#include "vtkXMLUnstructuredGridReader.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <vector>

#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

namespace mlr::guarded
{

namespace
{
#if defined(__SANITIZE_ADDRESS__)
constexpr bool AddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool AddressSanitizer = true;
#else
constexpr bool AddressSanitizer = false;
#endif
#else
constexpr bool AddressSanitizer = false;
#endif

/**
 * Counts VTK's errors while it is installed, whatever the caller did with VTK's messages: it
 * forwards them to the output window it replaced, or swallows them if warnings were off
 * (errors must still be counted then, so it turns the display on while it counts).
 */
class CountingOutputWindow : public vtkOutputWindow
{
public:
  static CountingOutputWindow* New();
  vtkTypeMacro(CountingOutputWindow, vtkOutputWindow);

  vtkSmartPointer<vtkOutputWindow> Next;
  bool Forward = true;
  std::size_t Errors = 0;

  void DisplayText(const char* text) override
  {
    if (this->Forward)
    {
      this->Next->DisplayText(text);
    }
  }
  void DisplayErrorText(const char* text) override
  {
    ++this->Errors;
    if (this->Forward)
    {
      this->Next->DisplayErrorText(text);
    }
  }
  void DisplayWarningText(const char* text) override
  {
    if (this->Forward)
    {
      this->Next->DisplayWarningText(text);
    }
  }
  void DisplayGenericWarningText(const char* text) override
  {
    if (this->Forward)
    {
      this->Next->DisplayGenericWarningText(text);
    }
  }
  void DisplayDebugText(const char* text) override
  {
    if (this->Forward)
    {
      this->Next->DisplayDebugText(text);
    }
  }

protected:
  CountingOutputWindow() = default;
};
vtkStandardNewMacro(CountingOutputWindow);

class ErrorCounter
{
public:
  ErrorCounter()
    : Previous(vtkOutputWindow::GetInstance())
    , Display(vtkObject::GetGlobalWarningDisplay())
  {
    this->Window->Next = this->Previous;
    this->Window->Forward = this->Display != 0;
    vtkObject::GlobalWarningDisplayOn();
    vtkOutputWindow::SetInstance(this->Window);
  }
  ~ErrorCounter()
  {
    vtkOutputWindow::SetInstance(this->Previous);
    vtkObject::SetGlobalWarningDisplay(this->Display);
  }
  ErrorCounter(const ErrorCounter&) = delete;
  ErrorCounter& operator=(const ErrorCounter&) = delete;

  std::size_t errors() const { return this->Window->Errors; }

private:
  vtkSmartPointer<vtkOutputWindow> Previous;
  int Display;
  vtkNew<CountingOutputWindow> Window;
};

std::string extensionOf(const std::string& path)
{
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

template <typename Reader>
vtkSmartPointer<vtkAlgorithm> fileReader(const std::string& path)
{
  auto reader = vtkSmartPointer<Reader>::New();
  reader->SetFileName(path.c_str());
  return reader;
}

/// VTK's readers by extension: what readSurfaceFile() reads, and names when it cannot.
struct VtkReader
{
  const char* extension;
  vtkSmartPointer<vtkAlgorithm> (*make)(const std::string& path);
};
const VtkReader VtkReaders[] = {
  { ".vtp", fileReader<vtkXMLPolyDataReader> },
  { ".vtu", fileReader<vtkXMLUnstructuredGridReader> },
  { ".vtk", fileReader<vtkGenericDataObjectReader> },
  { ".obj", fileReader<vtkOBJReader> },
  { ".ply", fileReader<vtkPLYReader> },
  { ".stl", fileReader<vtkSTLReader> },
};

/// "a .vtp .vtu ... or .stl file": VTK's extensions, then those of `more` not among them.
std::string extensionsText(const std::vector<std::string>& more)
{
  std::vector<std::string> all;
  for (const VtkReader& reader : VtkReaders)
  {
    all.emplace_back(reader.extension);
  }
  for (const std::string& extension : more)
  {
    if (std::find(all.begin(), all.end(), extension) == all.end())
    {
      all.push_back(extension);
    }
  }
  std::string text = "a";
  for (std::size_t i = 0; i < all.size(); ++i)
  {
    text += (i + 1 == all.size() && i > 0 ? " or " : " ") + all[i];
  }
  return text + " file";
}

/// The reader for `extension` on `path`; InputError for an extension we do not read (nor
/// the caller's reader, which reads `ownExtensions`).
vtkSmartPointer<vtkAlgorithm> makeReader(const std::string& path, const std::string& extension,
  const std::string& what, const std::vector<std::string>& ownExtensions = {})
{
  for (const VtkReader& reader : VtkReaders)
  {
    if (extension == reader.extension)
    {
      return reader.make(path);
    }
  }
  throw InputError(what + " has an unknown extension: give " + extensionsText(ownExtensions));
}

std::string secondsText(double seconds)
{
  std::ostringstream s;
  s << seconds << " s";
  return s.str();
}

/// Everything a file descriptor holds, from its start.
std::string contentsOf(int fd)
{
  std::string text;
  char buffer[4096];
  ssize_t n = 0;
  off_t offset = 0;
  while ((n = pread(fd, buffer, sizeof(buffer), offset)) > 0)
  {
    text.append(buffer, static_cast<std::size_t>(n));
    offset += n;
  }
  return text;
}

/// Closes a file descriptor when it goes out of scope.
struct Descriptor
{
  int fd = -1;
  ~Descriptor()
  {
    if (this->fd >= 0)
    {
      close(this->fd);
    }
  }
};

int memoryFile(const char* name)
{
  return static_cast<int>(syscall(SYS_memfd_create, name, MFD_CLOEXEC));
}

/// Exit statuses of the reading work.
enum ReadExit
{
  ReadOk = 0,
  ReadFailed = 2,  ///< VTK reported errors (they are in the messages)
  WriteFailed = 3, ///< the result could not be handed back
  OutOfMemory = ChildOutcome::OutOfMemoryStatus,
  Unexpected = ChildOutcome::ExceptionStatus,
};

/// Exit status of a child whose parent was gone before it could ask to die with it.
constexpr int ParentGone = 126;

/// Waits for `child` until it ends, whatever signals arrive; returns its status.
int reap(pid_t child, rusage& usage)
{
  int status = 0;
  while (wait4(child, &status, 0, &usage) < 0 && errno == EINTR)
  {
  }
  return status;
}
}

double TimeLimit::cpuSeconds(std::uint64_t bytes) const
{
  const double mebibytes = static_cast<double>(bytes) / (1024.0 * 1024.0);
  return std::max(1.0, std::round(this->baseSeconds + this->secondsPerMiB * mebibytes));
}

ChildOutcome runGuarded(const std::function<int()>& work, std::uint64_t memoryBytes,
  double cpuSeconds, double wallSeconds)
{
  Descriptor messages{ memoryFile("mlr-messages") };
  if (messages.fd < 0)
  {
    throw InputError(
      std::string("cannot start a reading process: no memory file (") + std::strerror(errno) + ")");
  }
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);

  // While the child runs, this thread takes SIGINT, SIGTERM and SIGCHLD with sigtimedwait, so
  // that an interrupt stops the child at once; a SIGCHLD left to its default would be
  // discarded, and one set to SIG_IGN would reap the child before we learn how it ended.
  sigset_t waited;
  sigemptyset(&waited);
  sigaddset(&waited, SIGINT);
  sigaddset(&waited, SIGTERM);
  sigaddset(&waited, SIGCHLD);
  sigset_t previousMask;
  pthread_sigmask(SIG_BLOCK, &waited, &previousMask);
  struct sigaction previousChild = {};
  sigaction(SIGCHLD, nullptr, &previousChild);
  const bool childIgnored = previousChild.sa_handler == SIG_IGN;
  if (childIgnored)
  {
    struct sigaction byDefault = {};
    byDefault.sa_handler = SIG_DFL;
    sigaction(SIGCHLD, &byDefault, nullptr);
  }
  auto restoreSignals = [&]
  {
    if (childIgnored)
    {
      sigaction(SIGCHLD, &previousChild, nullptr);
    }
    pthread_sigmask(SIG_SETMASK, &previousMask, nullptr);
  };

  const pid_t parent = getpid();
  const pid_t child = fork();
  if (child < 0)
  {
    const int error = errno;
    restoreSignals();
    throw InputError(std::string("cannot start a reading process: ") + std::strerror(error));
  }
  if (child == 0)
  {
    // Dies with the thread that forked it, whatever ends that: the check of getppid() closes
    // the window in which the parent died before the request was made.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent)
    {
      _exit(ParentGone);
    }
    // A crash or an expiry must end the child, not run the parent's handlers (sanitizers,
    // fuzzers); an interrupt ends it at once.
    for (int signal : { SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT, SIGINT, SIGTERM, SIGXCPU })
    {
      std::signal(signal, SIG_DFL);
    }
    pthread_sigmask(SIG_UNBLOCK, &waited, nullptr);
    // Its output goes to the messages, and it holds none of the caller's pipes to its output:
    // whoever reads them sees them end with the caller.
    dup2(messages.fd, STDOUT_FILENO);
    dup2(messages.fd, STDERR_FILENO);
    const rlimit noCore{ 0, 0 };
    setrlimit(RLIMIT_CORE, &noCore);
    if (memoryBytes > 0 && !AddressSanitizer) // ASan's shadow memory exceeds any limit
    {
      std::ifstream statm("/proc/self/statm");
      std::uint64_t pages = 0;
      statm >> pages;
      const std::uint64_t current = pages * static_cast<std::uint64_t>(sysconf(_SC_PAGE_SIZE));
      const rlimit addressSpace{ current + memoryBytes, current + memoryBytes };
      setrlimit(RLIMIT_AS, &addressSpace);
    }
    // SIGXCPU (fatal by default) at the limit, SIGKILL a second later if it is caught.
    const rlim_t cpu = static_cast<rlim_t>(std::max(1.0, std::ceil(cpuSeconds)));
    const rlimit cpuTime{ cpu, cpu + 1 };
    setrlimit(RLIMIT_CPU, &cpuTime);
    int code = Unexpected;
    try
    {
      code = work();
    }
    catch (const std::bad_alloc&)
    {
      code = OutOfMemory;
    }
    catch (...)
    {
      code = Unexpected;
    }
    std::cerr.flush();
    std::fflush(stderr);
    _exit(code);
  }

  ChildOutcome outcome;
  using Clock = std::chrono::steady_clock;
  const Clock::time_point deadline = Clock::now() +
    std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(wallSeconds));
  int status = 0;
  rusage usage = {};
  int interrupt = 0;
  bool otherChild = false;
  for (;;)
  {
    const pid_t ended = wait4(child, &status, WNOHANG, &usage);
    if (ended == child)
    {
      break;
    }
    if (ended < 0 && errno != EINTR)
    {
      const int error = errno;
      kill(child, SIGKILL);
      restoreSignals();
      throw InputError(std::string("lost the reading process: ") + std::strerror(error));
    }
    const Clock::time_point now = Clock::now();
    if (now >= deadline)
    {
      kill(child, SIGKILL);
      status = reap(child, usage);
      outcome.end = ChildOutcome::End::WallTime;
      break;
    }
    // Polls at least every 50 ms: a SIGCHLD may go to another thread.
    const auto left = std::min<Clock::duration>(deadline - now, std::chrono::milliseconds(50));
    const auto nanoseconds = std::chrono::duration_cast<std::chrono::nanoseconds>(left).count();
    const timespec timeout{ static_cast<time_t>(nanoseconds / 1000000000),
      static_cast<long>(nanoseconds % 1000000000) };
    siginfo_t info = {};
    const int signal = sigtimedwait(&waited, &info, &timeout);
    if (signal == SIGINT || signal == SIGTERM)
    {
      kill(child, SIGKILL);
      status = reap(child, usage);
      interrupt = signal;
      outcome.end = ChildOutcome::End::Interrupted;
      break;
    }
    if (signal == SIGCHLD && info.si_pid != child)
    {
      otherChild = true;
    }
  }
  // The signals taken here are raised again for the caller's handlers (or default actions),
  // delivered when the mask is restored.
  if (interrupt)
  {
    raise(interrupt);
  }
  if (otherChild)
  {
    raise(SIGCHLD);
  }
  restoreSignals();

  outcome.cpuSeconds = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
    1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  outcome.messages = contentsOf(messages.fd);
  if (outcome.end == ChildOutcome::End::Exited)
  {
    if (WIFEXITED(status))
    {
      outcome.code = WEXITSTATUS(status);
    }
    else if (WIFSIGNALED(status))
    {
      outcome.signal = WTERMSIG(status);
      // SIGKILL at the hard limit, a second after the soft one, if SIGXCPU was caught.
      const bool overTime = outcome.signal == SIGXCPU ||
        (outcome.signal == SIGKILL && outcome.cpuSeconds >= std::ceil(cpuSeconds));
      // Ctrl-C reaches the whole process group: the child may end of it before this thread
      // takes its own copy (raised for the caller when the mask was restored).
      const bool interrupted = outcome.signal == SIGINT || outcome.signal == SIGTERM;
      outcome.end = overTime ? ChildOutcome::End::CpuTime
        : interrupted        ? ChildOutcome::End::Interrupted
                             : ChildOutcome::End::Crashed;
    }
  }
  return outcome;
}

/// Whether every cell array of `output` is whole: offsets from 0 that never decrease and end
/// at the connectivity's length, and only ids of points the data set has. Readers of binary
/// formats (legacy .vtk 5.1) take offsets as the file gives them, and everything downstream
/// (the XML hand-back allocates the connectivity from the last offset) would trust them.
bool cellsAreWhole(vtkDataObject* output)
{
  auto* points = vtkPointSet::SafeDownCast(output);
  if (!points)
  {
    return true; // image and rectilinear data have implicit cells
  }
  std::vector<vtkCellArray*> arrays;
  if (auto* polygons = vtkPolyData::SafeDownCast(output))
  {
    arrays = { polygons->GetVerts(), polygons->GetLines(), polygons->GetPolys(),
      polygons->GetStrips() };
  }
  else if (auto* grid = vtkUnstructuredGrid::SafeDownCast(output))
  {
    arrays = { grid->GetCells() };
  }
  for (vtkCellArray* cells : arrays)
  {
    if (!cells)
    {
      continue;
    }
    if (!cells->IsValid())
    {
      return false;
    }
    vtkDataArray* connectivity = cells->GetConnectivityArray();
    if (connectivity && connectivity->GetNumberOfTuples() > 0)
    {
      double range[2];
      connectivity->GetRange(range, 0);
      if (range[0] < 0 || range[1] >= static_cast<double>(points->GetNumberOfPoints()))
      {
        return false;
      }
    }
  }
  return true;
}

vtkSmartPointer<vtkPolyData> polygonsOf(vtkAlgorithm* reader)
{
  ErrorCounter counter;
  reader->Update();
  vtkDataObject* output = reader->GetOutputDataObject(0);
  if (counter.errors() != 0 || reader->GetErrorCode() != 0 || !output)
  {
    return nullptr;
  }
  if (!cellsAreWhole(output))
  {
    std::cerr << "its cells do not fit together: their offsets do not match their lists of "
                 "points, or they name points the file does not have\n";
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
  if (auto* points = vtkPointSet::SafeDownCast(output); points && points->GetNumberOfCells() == 0)
  {
    // Points alone, such as sensors in a .vtu: the surface of no cells would drop them.
    auto cloud = vtkSmartPointer<vtkPolyData>::New();
    cloud->SetPoints(points->GetPoints());
    cloud->GetPointData()->ShallowCopy(points->GetPointData());
    cloud->GetFieldData()->ShallowCopy(points->GetFieldData());
    return cloud;
  }
  // Volumetric or other data sets: their surface, with the cell arrays carried along.
  vtkNew<vtkGeometryFilter> surface;
  surface->SetInputData(output);
  surface->Update();
  return counter.errors() == 0 ? surface->GetOutput() : nullptr;
}

vtkSmartPointer<vtkPolyData> readSurfaceFile(const std::string& path, const std::string& role,
  const ReadLimits& limits, const ReaderFactory& ownReader,
  const std::vector<std::string>& ownExtensions)
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
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error || size == 0)
  {
    throw InputError(what + " is empty");
  }

  const std::string extension = extensionOf(path);
  const vtkSmartPointer<vtkAlgorithm> own = ownReader ? ownReader(path, extension) : nullptr;
  const vtkSmartPointer<vtkAlgorithm> probe =
    own ? own : makeReader(path, extension, what, ownExtensions);
  if (auto* xml = vtkXMLReader::SafeDownCast(probe))
  {
    if (!xml->CanReadFile(path.c_str()))
    {
      throw InputError(what + " is not a VTK XML " +
        (extension == ".vtp" ? "PolyData" : "UnstructuredGrid") + " file");
    }
  }
  // What is known to crash or mislead VTK's readers, with a message naming the problem.
  if (own)
  {
    // The caller's reader checks its files itself.
  }
  else if (extension == ".obj")
  {
    checkObjFile(path, what);
  }
  else if (extension == ".stl")
  {
    checkStlFile(path, what);
  }
  else if (extension == ".ply")
  {
    checkPlyFile(path, what);
  }

  // Readers need some room whatever the limit.
  const std::uint64_t room = std::max<std::uint64_t>(
    MemoryBudget(limits.memoryBytes).limitBytes(), std::uint64_t(256) << 20);
  const double cpuSeconds = limits.time.cpuSeconds(size);
  const double wallSeconds = limits.time.wallSeconds(size);

  // The child hands its result back as VTK XML in a memory file.
  Descriptor data{ memoryFile("mlr-input") };
  if (data.fd < 0)
  {
    throw InputError("cannot read " + what + ": no memory file (" + std::strerror(errno) + ")");
  }
  const std::string dataPath = "/proc/self/fd/" + std::to_string(data.fd);
  const ChildOutcome outcome = runGuarded(
    [&]() -> int
    {
      if (!vtkObject::GetGlobalWarningDisplay())
      {
        // The error counter turns the display on; vtkLogger would then print what the caller
        // silenced.
        vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
      }
      const vtkSmartPointer<vtkPolyData> polygons =
        polygonsOf(own ? probe.GetPointer() : makeReader(path, extension, what).GetPointer());
      if (!polygons)
      {
        return ReadFailed;
      }
      // Handed back raw, uncompressed: the fastest for both sides.
      vtkNew<vtkXMLPolyDataWriter> writer;
      writer->SetInputData(polygons);
      writer->SetFileName(dataPath.c_str());
      writer->SetDataModeToAppended();
      writer->EncodeAppendedDataOff();
      writer->SetCompressorTypeToNone();
      writer->SetHeaderTypeToUInt64();
      return writer->Write() && writer->GetErrorCode() == 0 ? ReadOk : WriteFailed;
    },
    room, cpuSeconds, wallSeconds);

  using End = ChildOutcome::End;
  const std::string reader =
    own ? std::string(own->GetClassName()) : "VTK's " + extension + " reader";
  switch (outcome.end)
  {
    case End::Interrupted:
      throw ReadInterrupted("interrupted while reading " + what);
    case End::CpuTime:
    case End::WallTime:
    {
      std::ostringstream s;
      s << reader << " did not finish reading " << what << " within "
        << (outcome.end == End::CpuTime ? secondsText(cpuSeconds) + " of CPU time"
                                        : secondsText(wallSeconds) + " of wall-clock time")
        << " (the limit for a file of " << size << " bytes: " << secondsText(cpuSeconds)
        << " of CPU time and " << secondsText(wallSeconds)
        << " of wall-clock time): the file is damaged or makes the reader loop. Convert it to "
           "another format (for example .vtp, with ParaView) and try again";
      throw InputError(s.str());
    }
    case End::Crashed:
      // Memory over the limit often shows as a crash: VTK does not check its allocations.
      throw InputError(reader + " crashed (" + strsignal(outcome.signal) + ") on " + what +
        ": the file is damaged, truncated or not a " + extension +
        " file, or reading it needs more than the memory limit of " + gibibytes(room));
    case End::Exited:
      break;
  }
  if (outcome.code == ReadOk || outcome.code == ReadFailed || outcome.code == WriteFailed)
  {
    std::cerr << outcome.messages << std::flush; // VTK's own messages about the file
  }
  if (outcome.code == ReadFailed)
  {
    throw InputError("cannot read " + what + " (see the messages above)");
  }
  if (outcome.code == OutOfMemory)
  {
    throw InputError(reader + " ran out of memory on " + what +
      ": the file is damaged, or "
      "reading it needs more than the memory limit of " +
      gibibytes(room));
  }
  if (outcome.code != ReadOk)
  {
    throw InputError(reader + " failed (status " + std::to_string(outcome.code) + ") on " + what);
  }

  vtkNew<vtkXMLPolyDataReader> back;
  back->SetFileName(dataPath.c_str());
  vtkSmartPointer<vtkPolyData> polygons = polygonsOf(back);
  if (!polygons)
  {
    throw InputError(
      "cannot read " + what + ": its data did not come back from the reading process");
  }
  if (polygons->GetNumberOfPoints() == 0)
  {
    throw InputError(what + " has no points");
  }
  return polygons;
}

} // namespace mlr::guarded
