#include "InputFiles.h"

#include "EmbeddedData.h"
#include "FileChecks.h"
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
#include "vtkXMLPolyDataWriter.h"
#include "vtkXMLUnstructuredGridReader.h"

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

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


/// The reader for `extension` on `path`; InputError for an extension we do not read.
vtkSmartPointer<vtkAlgorithm> makeReader(
  const std::string& path, const std::string& extension, const std::string& what)
{
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
    xml->SetFileName(path.c_str());
    return xml;
  }
  if (extension == ".vtk")
  {
    auto legacy = vtkSmartPointer<vtkGenericDataObjectReader>::New();
    legacy->SetFileName(path.c_str());
    return legacy;
  }
  if (extension == ".obj")
  {
    auto obj = vtkSmartPointer<vtkOBJReader>::New();
    obj->SetFileName(path.c_str());
    return obj;
  }
  if (extension == ".ply")
  {
    auto ply = vtkSmartPointer<vtkPLYReader>::New();
    ply->SetFileName(path.c_str());
    return ply;
  }
  if (extension == ".stl")
  {
    auto stl = vtkSmartPointer<vtkSTLReader>::New();
    stl->SetFileName(path.c_str());
    return stl;
  }
  throw InputError(what + " has an unknown extension: give a .vtp .vtu .vtk .obj .ply or .stl file");
}

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

std::uint64_t physicalMemoryBytes()
{
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && pageSize > 0
    ? static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(pageSize)
    : std::uint64_t(8) << 30;
}

std::string gibibytes(std::uint64_t bytes)
{
  std::ostringstream s;
  s.precision(3);
  s << static_cast<double>(bytes) / (1024.0 * 1024.0 * 1024.0) << " GiB";
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

/// Exit codes of the child that reads.
enum ChildExit
{
  ReadOk = 0,
  ReadFailed = 2,   ///< VTK reported errors (they are in the messages)
  WriteFailed = 3,  ///< the result could not be handed back
  OutOfMemory = 4,
  Unexpected = 5,
};

/**
 * Runs the reader in a child process (fork) with its address space limited to `limit` bytes
 * more than it starts with, and returns what it read. VTK's messages from the child are
 * passed on unless it crashed (its crash report is no use to a user).
 */
vtkSmartPointer<vtkPolyData> readInChildProcess(const std::string& path,
  const std::string& extension, const std::string& what, std::uint64_t limit)
{
  Descriptor data{ static_cast<int>(syscall(SYS_memfd_create, "mlr-input", MFD_CLOEXEC)) };
  Descriptor messages{ static_cast<int>(syscall(SYS_memfd_create, "mlr-messages", MFD_CLOEXEC)) };
  if (data.fd < 0 || messages.fd < 0)
  {
    throw InputError(std::string("cannot read ") + what + ": no memory file (" +
      std::strerror(errno) + ")");
  }
  const std::string dataPath = "/proc/self/fd/" + std::to_string(data.fd);
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);

  const pid_t child = fork();
  if (child < 0)
  {
    throw InputError("cannot read " + what + ": cannot start a process (" + std::strerror(errno) + ")");
  }
  if (child == 0)
  {
    // A crash must end the child, not run the parent's handlers (sanitizers, fuzzers); an
    // interrupt ends it at once.
    for (int signal : { SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT, SIGINT, SIGTERM })
    {
      std::signal(signal, SIG_DFL);
    }
    dup2(messages.fd, STDERR_FILENO);
    if (!AddressSanitizer) // its shadow memory already exceeds any limit
    {
      std::ifstream statm("/proc/self/statm");
      std::uint64_t pages = 0;
      statm >> pages;
      const std::uint64_t current = pages * static_cast<std::uint64_t>(sysconf(_SC_PAGE_SIZE));
      // Readers need some room whatever the limit: at least 256 MiB.
      const std::uint64_t room = std::max<std::uint64_t>(limit, std::uint64_t(256) << 20);
      const rlimit addressSpace{ current + room, current + room };
      setrlimit(RLIMIT_AS, &addressSpace);
    }
    int code = Unexpected;
    try
    {
      const vtkSmartPointer<vtkAlgorithm> reader = makeReader(path, extension, what);
      const vtkSmartPointer<vtkPolyData> polygons = runReader(reader);
      code = ReadFailed;
      if (polygons)
      {
        // Handed back raw, uncompressed: the fastest for both sides.
        vtkNew<vtkXMLPolyDataWriter> writer;
        writer->SetInputData(polygons);
        writer->SetFileName(dataPath.c_str());
        writer->SetDataModeToAppended();
        writer->EncodeAppendedDataOff();
        writer->SetCompressorTypeToNone();
        writer->SetHeaderTypeToUInt64();
        code = writer->Write() && writer->GetErrorCode() == 0 ? ReadOk : WriteFailed;
      }
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
    _exit(code);
  }

  int status = 0;
  while (waitpid(child, &status, 0) < 0)
  {
    if (errno != EINTR)
    {
      throw InputError("cannot read " + what + ": lost its reading process (" + std::strerror(errno) + ")");
    }
  }
  if (WIFSIGNALED(status) && (WTERMSIG(status) == SIGINT || WTERMSIG(status) == SIGTERM))
  {
    throw InputError("interrupted while reading " + what + ": nothing was written");
  }
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == ReadOk || code == ReadFailed || code == WriteFailed)
  {
    std::cerr << contentsOf(messages.fd) << std::flush; // VTK's own messages about the file
  }
  if (code == ReadFailed)
  {
    throw InputError("cannot read " + what + " (see the messages above)");
  }
  if (code != ReadOk)
  {
    std::ostringstream s;
    s << "VTK's " << extension << " reader ";
    if (WIFSIGNALED(status))
    {
      s << "crashed (" << strsignal(WTERMSIG(status)) << ")";
    }
    else if (code == OutOfMemory)
    {
      s << "ran out of memory";
    }
    else
    {
      s << "failed (status " << code << ")";
    }
    s << " on " << what << ": the file is damaged, truncated or not a " << extension
      << " file, or reading it needs more than the memory limit of " << gibibytes(limit);
    throw InputError(s.str());
  }

  vtkNew<vtkXMLPolyDataReader> back;
  back->SetFileName(dataPath.c_str());
  vtkSmartPointer<vtkPolyData> polygons = runReader(back);
  if (!polygons)
  {
    throw InputError("cannot read " + what + ": its data did not come back from the reading process");
  }
  return polygons;
}
}

vtkSmartPointer<vtkPolyData> readSurfaceFile(
  const std::string& path, const std::string& role, std::uint64_t memoryLimitBytes)
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
  makeReader(path, extension, what); // refuses unknown extensions
  if (extension == ".vtp" || extension == ".vtu")
  {
    vtkSmartPointer<vtkXMLReader> xml = vtkXMLReader::SafeDownCast(makeReader(path, extension, what));
    if (!xml->CanReadFile(path.c_str()))
    {
      throw InputError(what + " is not a VTK XML " +
        (extension == ".vtp" ? "PolyData" : "UnstructuredGrid") + " file");
    }
  }
  // What is known to crash or mislead VTK's readers, with a message naming the problem.
  if (extension == ".obj")
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

  const std::uint64_t limit = memoryLimitBytes > 0 ? memoryLimitBytes : physicalMemoryBytes() / 2;
  vtkSmartPointer<vtkPolyData> data = readInChildProcess(path, extension, what, limit);
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
