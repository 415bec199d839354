// Guarded reading of surface files with VTK's readers (the library mlrGuardedRead).
//
// VTK 9.2's readers are not hardened against damaged files: fuzzing made them crash, allocate
// without bound and loop forever. A program that must survive any file (the command line, the
// readers fuzz target) reads through readSurfaceFile(): the file is first checked for what is
// known to crash the readers (FileChecks.h), then read in a child process under a memory
// limit, a CPU-time limit and a wall-clock limit, both scaled with the file's size. A crash,
// exhaustion or expiry there costs only that file: InputError names the file and the problem.
#pragma once

#include "vtkSmartPointer.h"

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

class vtkAlgorithm;
class vtkPolyData;

namespace mlr::guarded
{

/// An input that cannot be used: the message names the file and the problem.
class InputError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// The reading was stopped by SIGINT or SIGTERM.
class ReadInterrupted : public InputError
{
public:
  using InputError::InputError;
};

/**
 * The time a reader may take on a file of a given size: `baseSeconds` of CPU time plus
 * `secondsPerMiB` per MiB of file, and `wallFactor` times that of wall-clock time (a reader
 * that is blocked, or starved on a loaded machine, rather than spinning). The defaults allow
 * about 1 MiB/s, some ten times slower than VTK's slowest ASCII readers.
 */
struct TimeLimit
{
  double baseSeconds = 5;
  double secondsPerMiB = 1;
  double wallFactor = 4;

  /// CPU seconds for a file of `bytes`, in whole seconds (RLIMIT_CPU's unit), at least 1.
  double cpuSeconds(std::uint64_t bytes) const;
  double wallSeconds(std::uint64_t bytes) const
  {
    return this->wallFactor * this->cpuSeconds(bytes);
  }
};

struct ReadLimits
{
  /// Address space the reader may add to what the process uses; 0: half the physical memory.
  /// At least 256 MiB whatever is asked. Not applied under AddressSanitizer, whose shadow
  /// memory already exceeds any limit.
  std::uint64_t memoryBytes = 0;
  TimeLimit time;
};

/**
 * Reads a .vtp .vtu .vtk .obj .ply or .stl file as polygons (the surface of volumetric data),
 * keeping its cell arrays, or with `ownReader` a file of its own. `ownExtensions` are the
 * extensions `ownReader` reads, named beside VTK's readers' when a file has none of them. `role`
 * ("scene", "light", ...) names it in messages ("the scene file 'x.obj'"). Throws InputError when
 * the file is missing, empty, of an unknown extension, refused by the checks, reported as bad by
 * VTK, when the reader crashes, runs out of memory or time, or when the file has no points.
 *
 * VTK's messages from the reading process are passed on to stderr unless it crashed or was
 * stopped. SIGINT and SIGTERM reaching the calling thread while it waits stop the reading
 * process at once; they are then raised again for the caller's own handlers, and InputError
 * says the reading was interrupted. The reading process dies with the calling thread
 * (PR_SET_PDEATHSIG), so nothing is left running whatever ends the caller.
 */
/// A reader of the caller's own for some files (e.g. with materials), given the path and
/// its lowercase extension (".obj"); null for the files VTK's readers take as usual. It runs
/// in the guarded reading process, in place of VTK's reader and its checks.
using ReaderFactory = std::function<vtkSmartPointer<vtkAlgorithm>(
  const std::string& path, const std::string& extension)>;

vtkSmartPointer<vtkPolyData> readSurfaceFile(const std::string& path, const std::string& role,
  const ReadLimits& limits = {}, const ReaderFactory& ownReader = {},
  const std::vector<std::string>& ownExtensions = {});

/**
 * Runs `reader` in this process and returns its output as polygons (the surface of other
 * data sets, cell arrays kept); null if it reported an error. For trusted data (the files
 * compiled into a program); readSurfaceFile() uses it inside its reading process.
 */
vtkSmartPointer<vtkPolyData> polygonsOf(vtkAlgorithm* reader);

/// How a guarded child process ended.
struct ChildOutcome
{
  static constexpr int OutOfMemoryStatus = 4;
  static constexpr int ExceptionStatus = 5;

  enum class End
  {
    Exited,      ///< `code` holds its exit status
    Crashed,     ///< killed by `signal`
    CpuTime,     ///< over its CPU time
    WallTime,    ///< over its wall-clock time, and killed
    Interrupted, ///< SIGINT or SIGTERM reached the caller (the child was killed) or the child
  };
  End end = End::Exited;
  int code = 0;
  int signal = 0;
  double cpuSeconds = 0; ///< user + system time of the child
  std::string messages;  ///< what it wrote to stdout and stderr
};

/**
 * The guard readSurfaceFile() uses, for any work: runs `work` in a forked child whose exit
 * status is what `work` returns (ChildOutcome::OutOfMemoryStatus if it throws std::bad_alloc,
 * ChildOutcome::ExceptionStatus for any other exception), with stdout and stderr captured,
 * core dumps off, its address space limited to `memoryBytes` more than it starts with (0: no
 * limit), RLIMIT_CPU at `cpuSeconds` and a kill after `wallSeconds`. Returns once the child is
 * reaped. Throws InputError if no process can be started.
 */
ChildOutcome runGuarded(const std::function<int()>& work, std::uint64_t memoryBytes,
  double cpuSeconds, double wallSeconds);

} // namespace mlr::guarded
