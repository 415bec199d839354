// The guarded reading of input files (Apps/GuardedRead): every format is
// read with its cell arrays; bad files are refused with a message naming them; a reader that
// loops, blocks or crashes costs only its child process, which never outlives the caller.
//
// Each test runs in its own process (gtest_discover_tests), so "no child left" is checked with
// waitpid(-1): ECHILD means this process has no child at all, running or unreaped.
#include "GuardedRead.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDoubleArray.h"
#include "vtkNew.h"
#include "vtkObject.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnstructuredGrid.h"
#include "vtkXMLPolyDataReader.h"
#include "vtkXMLPolyDataWriter.h"
#include "vtkXMLUnstructuredGridWriter.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

namespace
{
namespace fs = std::filesystem;
using mlr::guarded::ChildOutcome;
using mlr::guarded::InputError;
using End = ChildOutcome::End;

class GuardedRead : public ::testing::Test
{
protected:
  void SetUp() override
  {
    char pattern[] = "/tmp/mlr-guarded-read-XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    this->Directory = pattern;
  }
  void TearDown() override
  {
    fs::remove_all(this->Directory);
    // No reading process may outlive its read, finished or not.
    errno = 0;
    EXPECT_EQ(waitpid(-1, nullptr, WNOHANG), -1) << "a child process is left";
    EXPECT_EQ(errno, ECHILD);
  }

  std::string write(const std::string& name, const std::string& bytes) const
  {
    const fs::path path = this->Directory / name;
    std::ofstream(path, std::ios::binary) << bytes;
    return path.string();
  }

  /// The message of the InputError that reading `path` throws, or "" if it reads.
  static std::string refusal(const std::string& path, const mlr::guarded::ReadLimits& limits = {})
  {
    try
    {
      mlr::guarded::readSurfaceFile(path, "scene", limits);
    }
    catch (const InputError& error)
    {
      return error.what();
    }
    return {};
  }

  fs::path Directory;
};

bool contains(const std::string& text, const std::string& part)
{
  return text.find(part) != std::string::npos;
}

/// A unit square in z = 0 as two triangles, with a cell array "Reflectance".
vtkNew<vtkPolyData> square()
{
  vtkNew<vtkPolyData> data;
  vtkNew<vtkPoints> points;
  points->InsertNextPoint(0, 0, 0);
  points->InsertNextPoint(1, 0, 0);
  points->InsertNextPoint(1, 1, 0);
  points->InsertNextPoint(0, 1, 0);
  vtkNew<vtkCellArray> triangles;
  const vtkIdType first[3] = { 0, 1, 2 }, second[3] = { 0, 2, 3 };
  triangles->InsertNextCell(3, first);
  triangles->InsertNextCell(3, second);
  vtkNew<vtkDoubleArray> reflectance;
  reflectance->SetName("Reflectance");
  reflectance->SetNumberOfComponents(3);
  reflectance->InsertNextTuple3(0.1, 0.2, 0.3);
  reflectance->InsertNextTuple3(0.4, 0.5, 0.6);
  data->SetPoints(points);
  data->SetPolys(triangles);
  data->GetCellData()->AddArray(reflectance);
  return data;
}

const char* const ObjSquare = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

// --- What reads -----------------------------------------------------------------------------
TEST_F(GuardedRead, ReadsEveryFormat)
{
  const std::string files[] = {
    this->write("square.obj", ObjSquare),
    this->write("square.stl",
      "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\n"
      "endloop\nendfacet\nendsolid s\n"),
    this->write("square.ply",
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n"),
    this->write("square.vtk",
      "# vtk DataFile Version 4.2\nsquare\nASCII\nDATASET POLYDATA\nPOINTS 4 float\n"
      "0 0 0 1 0 0 1 1 0 0 1 0\nPOLYGONS 1 5\n4 0 1 2 3\n"),
  };
  for (const std::string& file : files)
  {
    const vtkSmartPointer<vtkPolyData> data = mlr::guarded::readSurfaceFile(file, "scene");
    ASSERT_TRUE(data) << file;
    EXPECT_GE(data->GetNumberOfPoints(), 3) << file;
    EXPECT_GE(data->GetNumberOfPolys(), 1) << file;
  }
}

TEST_F(GuardedRead, KeepsCellArraysOfXmlFiles)
{
  const std::string polygons = (this->Directory / "square.vtp").string();
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetInputData(square());
  writer->SetFileName(polygons.c_str());
  ASSERT_TRUE(writer->Write());
  const vtkSmartPointer<vtkPolyData> data = mlr::guarded::readSurfaceFile(polygons, "scene");
  ASSERT_EQ(data->GetNumberOfPolys(), 2);
  vtkDataArray* reflectance = data->GetCellData()->GetArray("Reflectance");
  ASSERT_NE(reflectance, nullptr);
  EXPECT_DOUBLE_EQ(reflectance->GetComponent(1, 2), 0.6);

  // A tetrahedron: its surface, four triangles, each with the tetrahedron's value.
  vtkNew<vtkUnstructuredGrid> grid;
  vtkNew<vtkPoints> corners;
  corners->InsertNextPoint(0, 0, 0);
  corners->InsertNextPoint(1, 0, 0);
  corners->InsertNextPoint(0, 1, 0);
  corners->InsertNextPoint(0, 0, 1);
  grid->SetPoints(corners);
  const vtkIdType tetra[4] = { 0, 1, 2, 3 };
  grid->InsertNextCell(VTK_TETRA, 4, tetra);
  vtkNew<vtkDoubleArray> value;
  value->SetName("Value");
  value->InsertNextValue(7);
  grid->GetCellData()->AddArray(value);
  const std::string volume = (this->Directory / "tetra.vtu").string();
  vtkNew<vtkXMLUnstructuredGridWriter> gridWriter;
  gridWriter->SetInputData(grid);
  gridWriter->SetFileName(volume.c_str());
  ASSERT_TRUE(gridWriter->Write());
  const vtkSmartPointer<vtkPolyData> surface = mlr::guarded::readSurfaceFile(volume, "scene");
  EXPECT_EQ(surface->GetNumberOfPolys(), 4);
  ASSERT_NE(surface->GetCellData()->GetArray("Value"), nullptr);
  EXPECT_EQ(surface->GetCellData()->GetArray("Value")->GetRange()[0], 7);
}

// --- What is refused before reading ---------------------------------------------------------
TEST_F(GuardedRead, RefusesMissingEmptyAndUnknownFiles)
{
  EXPECT_TRUE(contains(refusal((this->Directory / "none.obj").string()),
    "the scene file '" + (this->Directory / "none.obj").string() +
      "' does not exist or is not a file"));
  EXPECT_TRUE(contains(refusal(this->Directory.string()), "does not exist or is not a file"));
  EXPECT_TRUE(contains(refusal(this->write("empty.vtp", "")), "empty.vtp' is empty"));
  EXPECT_TRUE(contains(refusal(this->write("scene.dae", "<COLLADA/>")),
    "has an unknown extension: give a .vtp .vtu .vtk .obj .ply or .stl file"));
  EXPECT_TRUE(
    contains(refusal(this->write("obj.vtp", ObjSquare)), "is not a VTK XML PolyData file"));
}

TEST_F(GuardedRead, ChecksRefuseWhatCrashesVtksReaders)
{
  EXPECT_TRUE(
    contains(refusal(this->write("texture.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/2 3/3\n")),
      "texture.obj', line 4: '1/1' names texture coordinate 1 but the file defines 0 (vt lines)"));
  EXPECT_TRUE(contains(refusal(this->write("head.ply", "ply\nformat ascii 1.0\nend_header\n")),
    "is not a PLY file VTK can read: no element 'vertex' with properties x, y and z"));
  std::string stl(84, '\0');
  stl[80] = 100; // 100 triangles, none there
  EXPECT_TRUE(contains(refusal(this->write("count.stl", stl)),
    "is a binary STL file whose header counts 100 triangles, but it holds only 0"));
}

TEST_F(GuardedRead, VtkErrorsRefuseTheFileEvenWithWarningsOff)
{
  const std::string path = (this->Directory / "cut.vtp").string();
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetInputData(square());
  writer->SetFileName(path.c_str());
  writer->SetDataModeToAscii();
  ASSERT_TRUE(writer->Write());
  std::ifstream in(path);
  const std::string whole((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  this->write("cut.vtp", whole.substr(0, whole.find("<Polys>")));
  vtkObject::GlobalWarningDisplayOff();
  const std::string message = refusal(path);
  vtkObject::GlobalWarningDisplayOn();
  EXPECT_TRUE(contains(message, "cannot read the scene file '" + path + "'")) << message;
}

// --- A reader that does not finish ----------------------------------------------------------
TEST_F(GuardedRead, LegacyReaderThatLoopsIsStoppedByTheCpuLimit)
{
  // The fuzz regression (its first byte chose the .vtk extension): VTK 9.2's legacy reader
  // never returns on it.
  std::ifstream in(MLR_HANG_REGRESSION, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 1u);
  const std::string path = this->write("hang.vtk", bytes.substr(1));
  mlr::guarded::ReadLimits limits;
  limits.time.baseSeconds = 1;
  limits.time.wallFactor = 30; // the CPU limit must be what stops it, however loaded the machine
  const std::string message = refusal(path, limits);
  EXPECT_TRUE(contains(message,
    "VTK's .vtk reader did not finish reading the scene file '" + path +
      "' within 1 s of CPU time"))
    << message;
  EXPECT_TRUE(contains(message, "Convert it to another format")) << message;
}

TEST_F(GuardedRead, TimeLimitGrowsWithTheFile)
{
  const mlr::guarded::TimeLimit limit;
  EXPECT_EQ(limit.cpuSeconds(300), 5);          // 5 s + 1 s per MiB, in whole seconds
  EXPECT_EQ(limit.cpuSeconds(100u << 20), 105); // 100 MiB
  EXPECT_EQ(limit.wallSeconds(100u << 20), 420);
}

// --- The guard itself -----------------------------------------------------------------------
TEST_F(GuardedRead, ChildStatusAndMessagesComeBack)
{
  const ChildOutcome outcome = mlr::guarded::runGuarded(
    []
    {
      std::fputs("a message\n", stderr);
      return 7;
    },
    0, 10, 60);
  EXPECT_EQ(outcome.end, End::Exited);
  EXPECT_EQ(outcome.code, 7);
  EXPECT_EQ(outcome.messages, "a message\n");
}

TEST_F(GuardedRead, SpinningChildIsStoppedByItsCpuTime)
{
  const ChildOutcome outcome = mlr::guarded::runGuarded(
    []
    {
      for (volatile unsigned long i = 0;; i = i + 1)
      {
      }
      return 0;
    },
    0, 1, 600);
  EXPECT_EQ(outcome.end, End::CpuTime);
  // It spun until stopped; the kernel's count against RLIMIT_CPU and the CPU time getrusage
  // reports differ by up to a few scheduler ticks.
  EXPECT_GT(outcome.cpuSeconds, 0.5);
}

TEST_F(GuardedRead, BlockedChildIsStoppedByTheWallClock)
{
  const ChildOutcome outcome = mlr::guarded::runGuarded(
    []
    {
      pause(); // uses no CPU time: only the wall-clock limit ends it
      return 0;
    },
    0, 60, 0.5);
  EXPECT_EQ(outcome.end, End::WallTime);
}

TEST_F(GuardedRead, CrashCostsOnlyTheChild)
{
  const ChildOutcome outcome = mlr::guarded::runGuarded(
    []
    {
      std::raise(SIGSEGV);
      return 0;
    },
    0, 10, 60);
  EXPECT_EQ(outcome.end, End::Crashed);
  EXPECT_EQ(outcome.signal, SIGSEGV);
}

std::atomic<int> Terminations{ 0 };
extern "C" void countTermination(int)
{
  ++Terminations;
}

TEST_F(GuardedRead, InterruptStopsTheChildAndReachesTheCallersHandler)
{
  struct sigaction counting = {}, previous = {};
  counting.sa_handler = countTermination;
  sigaction(SIGTERM, &counting, &previous);
  Terminations = 0;
  // The child sends the caller SIGTERM, then waits for ever.
  const ChildOutcome outcome = mlr::guarded::runGuarded(
    []
    {
      kill(getppid(), SIGTERM);
      pause();
      return 0;
    },
    0, 60, 600);
  sigaction(SIGTERM, &previous, nullptr);
  EXPECT_EQ(outcome.end, End::Interrupted);
  EXPECT_EQ(Terminations, 1);
}

TEST_F(GuardedRead, ChildDiesWithItsParent)
{
  // This process adopts orphans, so that it can wait for the reading child of a parent that
  // was killed.
  ASSERT_EQ(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  int pipeEnds[2];
  ASSERT_EQ(pipe(pipeEnds), 0);
  const pid_t parent = fork();
  ASSERT_GE(parent, 0);
  if (parent == 0)
  {
    close(pipeEnds[0]);
    mlr::guarded::runGuarded(
      [&]
      {
        const pid_t self = getpid();
        if (::write(pipeEnds[1], &self, sizeof(self)) != sizeof(self))
        {
          return 1;
        }
        pause();
        return 0;
      },
      0, 600, 600);
    _exit(0);
  }
  close(pipeEnds[1]);
  pid_t reader = 0;
  ASSERT_EQ(read(pipeEnds[0], &reader, sizeof(reader)), static_cast<ssize_t>(sizeof(reader)));
  close(pipeEnds[0]);
  kill(parent, SIGKILL);
  int status = 0;
  ASSERT_EQ(waitpid(parent, &status, 0), parent);

  // The orphan is now this process's child: it must end by itself (killed by its parent's
  // death), which waiting up to a minute tells apart from running on.
  pid_t ended = 0;
  for (int i = 0; i < 600 && ended == 0; ++i)
  {
    ended = waitpid(reader, &status, WNOHANG);
    if (ended == 0)
    {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  if (ended == 0)
  {
    kill(reader, SIGKILL);
    waitpid(reader, &status, 0);
  }
  prctl(PR_SET_CHILD_SUBREAPER, 0);
  ASSERT_EQ(ended, reader) << "the reading process outlived its parent";
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
}
}
