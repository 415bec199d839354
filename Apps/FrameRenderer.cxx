#include "FrameRenderer.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCellDataToPointData.h"
#include "vtkDataArray.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkPolyDataNormals.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkWindowToImageFilter.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace mlr::cli
{

namespace
{
constexpr int PictureSize = 640;
/// The Cornell box camera's field of view: a 25 mm film at 35 mm focal length.
constexpr double ViewAngleDegrees = 39.3;

double luminance(const double rgb[3])
{
  return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}
}

struct FrameRenderer::Pipeline
{
  vtkNew<vtkRenderWindow> window;
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkPolyData> scene;
  vtkNew<vtkPolyDataNormals> creases;
  // The element mesh split along its creases, computed once: it is the same in every frame.
  vtkNew<vtkPolyData> split;
  vtkSmartPointer<vtkPoints> splitPoints; // held: a new mesh cannot take their addresses
  vtkSmartPointer<vtkCellArray> splitPolys;
  vtkNew<vtkPolyData> frame; ///< `split` with the frame's Radiosity
  vtkNew<vtkCellDataToPointData> smooth;
  vtkNew<vtkPolyData> shown;
  vtkNew<vtkPolyDataMapper> sceneMapper;
  vtkNew<vtkActor> sceneActor;
  vtkNew<vtkActor> lightActor;
  double exposure = 1.0;
};

FrameRenderer::FrameRenderer(vtkPolyData* light, const double bounds[6], const double* up)
  : Internals(new Pipeline)
{
  Pipeline& p = *this->Internals;
  p.window->SetOffScreenRendering(1);
  p.window->SetSize(PictureSize, PictureSize);
  p.window->SetMultiSamples(8);
  p.window->AddRenderer(p.renderer);
  p.renderer->SetBackground(0, 0, 0);

  // Radiosity is smooth within a surface but jumps at its creases (a wall meets the floor):
  // split the points along creases, then average the cells' radiosity at the points, which
  // also softens the Monte Carlo noise of single elements.
  p.creases->SetInputData(p.scene);
  p.creases->SplittingOn();
  p.creases->SetFeatureAngle(30);
  p.creases->ConsistencyOff();
  p.creases->AutoOrientNormalsOff();
  p.creases->ComputeCellNormalsOff();
  p.creases->ComputePointNormalsOff();
  p.smooth->SetInputData(p.frame);
  p.smooth->ProcessAllArraysOff();
  p.smooth->AddCellDataArray("Radiosity");
  p.sceneMapper->SetInputData(p.shown);
  p.sceneMapper->SetScalarModeToUsePointData();
  p.sceneMapper->SetColorModeToDirectScalars();
  p.sceneActor->SetMapper(p.sceneMapper);
  p.sceneActor->GetProperty()->LightingOff();
  p.renderer->AddActor(p.sceneActor);

  if (light) // none when the scene's own surfaces emit
  {
    vtkNew<vtkPolyDataMapper> lightMapper;
    lightMapper->SetInputData(light);
    lightMapper->ScalarVisibilityOff();
    p.lightActor->SetMapper(lightMapper);
    p.lightActor->GetProperty()->SetColor(1, 1, 1);
    p.lightActor->GetProperty()->LightingOff();
    p.renderer->AddActor(p.lightActor);
  }

  // Look along +z at the bounding box, from far enough for its front face to fill the view.
  const double centre[3] = { 0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]),
    0.5 * (bounds[4] + bounds[5]) };
  const double halfSize = 0.5 * std::max(bounds[1] - bounds[0], bounds[3] - bounds[2]);
  const double distance = halfSize / std::tan(0.5 * ViewAngleDegrees * M_PI / 180.0) +
    (centre[2] - bounds[4]);
  vtkCamera* camera = p.renderer->GetActiveCamera();
  camera->SetViewAngle(ViewAngleDegrees);
  camera->SetFocalPoint(centre);
  camera->SetPosition(centre[0], centre[1], centre[2] - std::max(distance, 1e-6));
  camera->SetViewUp(0, 1, 0);
  if (up)
  {
    // An aerial view: from 35 degrees above the horizon, over a corner, framing the bounding
    // sphere.
    const double norm = std::sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]);
    double u[3] = { up[0] / norm, up[1] / norm, up[2] / norm };
    double a[3] = { 1, 0, 0 };
    if (std::abs(u[0]) > 0.9)
    {
      a[0] = 0;
      a[1] = 1;
    }
    double b[3] = { u[1] * a[2] - u[2] * a[1], u[2] * a[0] - u[0] * a[2], u[0] * a[1] - u[1] * a[0] };
    const double bn = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    double c[3] = { u[1] * b[2] - u[2] * b[1], u[2] * b[0] - u[0] * b[2], u[0] * b[1] - u[1] * b[0] };
    const double radius = 0.5 * std::sqrt((bounds[1] - bounds[0]) * (bounds[1] - bounds[0]) +
      (bounds[3] - bounds[2]) * (bounds[3] - bounds[2]) + (bounds[5] - bounds[4]) * (bounds[5] - bounds[4]));
    const double far = radius / std::sin(0.5 * ViewAngleDegrees * M_PI / 180.0);
    const double elevation = 35 * M_PI / 180;
    double from[3];
    for (int i = 0; i < 3; ++i)
    {
      const double horizontal = (b[i] / bn + c[i] / bn) / std::sqrt(2.0);
      from[i] = centre[i] + far * (std::cos(elevation) * horizontal + std::sin(elevation) * u[i]);
    }
    camera->SetPosition(from);
    camera->SetViewUp(u);
  }
}

FrameRenderer::~FrameRenderer() = default;

double FrameRenderer::brightLevel(vtkPolyData* elements)
{
  vtkDataArray* radiosity = elements->GetCellData()->GetArray("Radiosity");
  if (!radiosity || radiosity->GetNumberOfTuples() == 0)
  {
    return 0.0;
  }
  std::vector<double> values(static_cast<std::size_t>(radiosity->GetNumberOfTuples()));
  for (vtkIdType i = 0; i < radiosity->GetNumberOfTuples(); ++i)
  {
    values[static_cast<std::size_t>(i)] = luminance(radiosity->GetTuple3(i));
  }
  const auto rank = values.begin() + static_cast<long>(0.99 * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), rank, values.end());
  return *rank;
}

void FrameRenderer::setBrightLevel(double radiosity)
{
  // 1 - exp(-2) = 0.86: the bright level lands just below white and brighter spots
  // (the hot spot under the light) still show some gradation instead of clipping.
  this->Internals->exposure = radiosity > 0 ? 2.0 / radiosity : 1.0;
}

void FrameRenderer::render(
  vtkPolyData* elements, const double lightTranslation[3], const std::filesystem::path& png)
{
  Pipeline& p = *this->Internals;
  if (elements->GetPoints() != p.splitPoints || elements->GetPolys() != p.splitPolys ||
    p.split->GetNumberOfCells() != elements->GetNumberOfCells())
  {
    // Splitting keeps the cells (all triangles) in their order: the frame's cell data fits.
    p.scene->CopyStructure(elements);
    p.creases->Update();
    p.split->CopyStructure(p.creases->GetOutput());
    p.splitPoints = elements->GetPoints();
    p.splitPolys = elements->GetPolys();
  }
  p.frame->CopyStructure(p.split);
  p.frame->GetCellData()->Initialize();
  if (vtkDataArray* cellRadiosity = elements->GetCellData()->GetArray("Radiosity"))
  {
    p.frame->GetCellData()->AddArray(cellRadiosity);
  }
  p.smooth->Update();
  p.shown->ShallowCopy(p.smooth->GetOutput());
  vtkDataArray* radiosity = p.shown->GetPointData()->GetArray("Radiosity");
  const vtkIdType points = p.shown->GetNumberOfPoints();
  vtkNew<vtkUnsignedCharArray> colours;
  colours->SetNumberOfComponents(3);
  colours->SetNumberOfTuples(points);
  for (vtkIdType i = 0; i < points; ++i)
  {
    double rgb[3] = { 0, 0, 0 };
    if (radiosity)
    {
      radiosity->GetTuple(i, rgb);
    }
    for (int c = 0; c < 3; ++c)
    {
      const double mapped = 1.0 - std::exp(-p.exposure * std::max(rgb[c], 0.0));
      colours->SetTypedComponent(
        i, c, static_cast<unsigned char>(std::lround(255.0 * std::pow(mapped, 1.0 / 2.2))));
    }
  }
  p.shown->GetPointData()->SetScalars(colours);
  p.lightActor->SetPosition(lightTranslation[0], lightTranslation[1], lightTranslation[2]);
  p.renderer->ResetCameraClippingRange();
  p.window->Render();

  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(p.window);
  grab->ReadFrontBufferOff();
  grab->ShouldRerenderOff(); // rendered just above: a second render cost as much again
  vtkNew<vtkPNGWriter> writer;
  writer->SetInputConnection(grab->GetOutputPort());
  writer->SetFileName(png.string().c_str());
  writer->Write();
  if (writer->GetErrorCode() != 0)
  {
    throw std::runtime_error("cannot write the picture '" + png.string() + "'");
  }
}

namespace
{
std::string findInPath(const std::string& program)
{
  const char* path = std::getenv("PATH");
  std::istringstream directories(path ? path : "/usr/bin:/bin");
  std::string directory;
  while (std::getline(directories, directory, ':'))
  {
    const std::string candidate = (directory.empty() ? "." : directory) + "/" + program;
    if (access(candidate.c_str(), X_OK) == 0)
    {
      return candidate;
    }
  }
  return {};
}

std::string displayVariable()
{
  const char* display = std::getenv("DISPLAY");
  return display ? display : "";
}

/// Stops the server: SIGTERM, then SIGKILL if it has not exited within 10 s.
void stopServer(pid_t server)
{
  kill(server, SIGTERM);
  for (int i = 0; i < 1000; ++i)
  {
    const pid_t done = waitpid(server, nullptr, WNOHANG);
    if (done == server || (done < 0 && errno != EINTR))
    {
      return;
    }
    usleep(10000);
  }
  kill(server, SIGKILL);
  while (waitpid(server, nullptr, 0) < 0 && errno == EINTR)
  {
  }
}

enum class Startup
{
  Ready,   ///< the server wrote its display number
  Exited,  ///< it closed the pipe without one: the number is taken, or it cannot start
  TimedOut ///< still nothing after the time allowed
};

/// Reads what the server writes to `fd` until a newline, the pipe's end or `seconds`.
Startup readReadyLine(int fd, int seconds)
{
  std::string line;
  for (int waited = 0; waited < seconds * 10;)
  {
    pollfd ready{ fd, POLLIN, 0 };
    const int polled = poll(&ready, 1, 100);
    if (polled < 0 && errno == EINTR)
    {
      continue;
    }
    if (polled == 0)
    {
      ++waited;
      continue;
    }
    char c;
    const ssize_t n = read(fd, &c, 1);
    if (n < 0 && errno == EINTR)
    {
      continue;
    }
    if (n <= 0 || c == '\n')
    {
      return line.empty() ? Startup::Exited : Startup::Ready;
    }
    line += c;
  }
  return Startup::TimedOut;
}

std::string fileText(int fd)
{
  std::string text;
  char buffer[4096];
  lseek(fd, 0, SEEK_SET);
  for (ssize_t n; (n = read(fd, buffer, sizeof(buffer))) > 0;)
  {
    text.append(buffer, static_cast<std::size_t>(n));
  }
  text.erase(text.find_last_not_of(" \n") + 1);
  return text;
}
}

void PictureDisplay::checkAvailable()
{
  if (displayVariable().empty() && findInPath("Xvfb").empty())
  {
    throw std::runtime_error("--png needs an X display: set DISPLAY, or install Xvfb "
                             "(Debian's package xvfb) to render the pictures off-screen");
  }
}

PictureDisplay::PictureDisplay()
  : Name(displayVariable())
{
  if (!this->Name.empty())
  {
    return;
  }
  checkAvailable();
  const std::string xvfb = findInPath("Xvfb");
  const pid_t parent = getpid();
  std::mt19937 random(std::random_device{}());
  std::uniform_int_distribution<int> numbers(1000, 29999);
  std::string failure = "no attempt";
  for (int attempt = 0; attempt < 20; ++attempt)
  {
    // Everything the child needs is prepared before fork(): this process has threads, and the
    // child may only make async-signal-safe calls until it runs Xvfb.
    const std::string display = ":" + std::to_string(numbers(random));
    int ready[2]; // Xvfb writes the display number here once it accepts connections
    if (pipe2(ready, O_CLOEXEC) != 0)
    {
      throw std::runtime_error(std::string("cannot start Xvfb: ") + std::strerror(errno));
    }
    char logName[] = "/tmp/mlr-xvfb-XXXXXX";
    const int log = mkostemp(logName, O_CLOEXEC);
    if (log >= 0)
    {
      unlink(logName);
    }
    const std::string readyFd = std::to_string(ready[1]);
    const char* arguments[] = { "Xvfb", display.c_str(), "-displayfd", readyFd.c_str(), "-screen",
      "0", "1280x1024x24", "-nolisten", "tcp", "-noreset", nullptr };
    const pid_t child = fork();
    if (child == 0)
    {
      // The server must not outlive this process, even one that is killed or crashes.
      prctl(PR_SET_PDEATHSIG, SIGTERM);
      if (getppid() != parent)
      {
        _exit(127);
      }
      // Its own process group: Ctrl-C interrupts the run, which then stops the server itself
      // after the render window has closed its connection.
      setpgid(0, 0);
      const int null = open("/dev/null", O_RDONLY);
      dup2(null, 0);
      if (log >= 0)
      {
        dup2(log, 1);
        dup2(log, 2);
      }
      fcntl(ready[1], F_SETFD, 0); // inherited by Xvfb
      execv(xvfb.c_str(), const_cast<char* const*>(arguments));
      _exit(127);
    }
    close(ready[1]);
    if (child < 0)
    {
      close(ready[0]);
      if (log >= 0)
      {
        close(log);
      }
      throw std::runtime_error(std::string("cannot start Xvfb: ") + std::strerror(errno));
    }
    const Startup startup = readReadyLine(ready[0], 30);
    close(ready[0]);
    if (startup == Startup::Ready)
    {
      if (log >= 0)
      {
        close(log);
      }
      this->Server = child;
      this->Name = display;
      setenv("DISPLAY", display.c_str(), 1);
      return;
    }
    stopServer(child);
    failure = display + ": " + (log >= 0 ? fileText(log) : std::string("no log"));
    if (log >= 0)
    {
      close(log);
    }
    if (startup == Startup::TimedOut)
    {
      // Another number would not help a server that hangs.
      throw std::runtime_error("--png: Xvfb did not accept connections within 30 s: " + failure);
    }
  }
  throw std::runtime_error("--png: Xvfb did not start: " + failure);
}

PictureDisplay::~PictureDisplay()
{
  if (this->Server > 0)
  {
    stopServer(this->Server);
  }
}

} // namespace mlr::cli
