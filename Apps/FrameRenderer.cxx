#include "FrameRenderer.h"

#include "Rgb.h"
#include "SeriesWriter.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkIdList.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkStaticCellLocator.h"
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
/// The plugin's Light representation (Plugin/MovingLightRadiosity.xml): the same lamp in
/// ParaView and in the pictures.
constexpr double LightColor[3] = { 1.0, 0.85, 0.2 };
/// Rays per side of the grid each candidate camera casts to count the lit sides it sees.
constexpr int ViewRays = 32;
/// Surfaces crossed by the view's axis that get a candidate camera just past them.
constexpr int InsideCandidates = 4;
/// The outside camera stays unless under this share of its rays meet a lit side...
constexpr double OutsideEnough = 0.2;
/// ... and an inside one meets at least this many times as many (and at least MinimumLit).
constexpr double InsideGain = 2;
constexpr double MinimumLit = 0.05;
/// Of the inside cameras, the nearest to the outside that sees this share of the best's.
constexpr double NearlyTheBest = 0.8;
/// An inside camera's widest view, degrees: wider distorts more than it shows.
constexpr double WidestViewDegrees = 90;

double dot(const double a[3], const double b[3])
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
}

struct FrameRenderer::Pipeline
{
  vtkNew<vtkRenderWindow> window;
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkPolyData> elements; ///< the frame's Elements, shallow copies
  vtkNew<vtkPolyData> light;    ///< the frame's Light
  vtkNew<vtkPolyDataMapper> elementsMapper;
  vtkNew<vtkPolyDataMapper> lightMapper;
  vtkNew<vtkActor> elementsActor;
  vtkNew<vtkActor> lightActor;

  double bounds[6] = { 0, 0, 0, 0, 0, 0 };
  bool aerial = false;
  bool chosen = false;
  View view;
  // The sampled frames: the element mesh (the same in every frame) and, per cell, the summed
  // luminance of each side's radiosity.
  vtkNew<vtkPolyData> mesh;
  std::vector<double> front, back;

  /// The share of a grid of rays from `eye` along +z (y up) over a view of `angle` degrees
  /// whose first surface shows the eye a lit side.
  double litShare(vtkStaticCellLocator* locator, const double eye[3], double angle) const;
};

double FrameRenderer::Pipeline::litShare(
  vtkStaticCellLocator* locator, const double eye[3], double angle) const
{
  double most = 0;
  for (std::size_t c = 0; c < this->front.size(); ++c)
  {
    most = std::max({ most, this->front[c], this->back[c] });
  }
  if (!(most > 0))
  {
    return 0;
  }
  const double lit = 1e-2 * most;
  const double reach = 4 *
      std::sqrt((this->bounds[1] - this->bounds[0]) * (this->bounds[1] - this->bounds[0]) +
        (this->bounds[3] - this->bounds[2]) * (this->bounds[3] - this->bounds[2]) +
        (this->bounds[5] - this->bounds[4]) * (this->bounds[5] - this->bounds[4])) +
    std::abs(eye[2] - this->bounds[4]);
  const double spread = std::tan(0.5 * angle * M_PI / 180.0);
  // Rays through an edge between two triangles must not slip through.
  const double tolerance = 1e-9 * reach;
  vtkNew<vtkIdList> ids;
  int seen = 0;
  for (int i = 0; i < ViewRays; ++i)
  {
    for (int j = 0; j < ViewRays; ++j)
    {
      double direction[3] = { spread * (2 * (i + 0.5) / ViewRays - 1),
        spread * (2 * (j + 0.5) / ViewRays - 1), 1 };
      const double norm = std::sqrt(dot(direction, direction));
      double end[3];
      for (int k = 0; k < 3; ++k)
      {
        direction[k] /= norm;
        end[k] = eye[k] + reach * direction[k];
      }
      double t = 0, x[3], pcoords[3];
      int subId = 0;
      vtkIdType cell = -1;
      if (!locator->IntersectWithLine(eye, end, tolerance, t, x, pcoords, subId, cell) || cell < 0)
      {
        continue;
      }
      this->mesh->GetCellPoints(cell, ids);
      if (ids->GetNumberOfIds() < 3)
      {
        continue;
      }
      double p0[3], p1[3], p2[3];
      this->mesh->GetPoint(ids->GetId(0), p0);
      this->mesh->GetPoint(ids->GetId(1), p1);
      this->mesh->GetPoint(ids->GetId(2), p2);
      const double a[3] = { p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2] };
      const double b[3] = { p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2] };
      const double normal[3] = { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0] };
      // The front is the side the right-hand normal points to.
      const auto c = static_cast<std::size_t>(cell);
      const double shown = dot(normal, direction) < 0 ? this->front[c] : this->back[c];
      seen += shown > lit ? 1 : 0;
    }
  }
  return static_cast<double>(seen) / (ViewRays * ViewRays);
}

FrameRenderer::FrameRenderer(const double bounds[6], const double* up)
  : Internals(new Pipeline)
{
  Pipeline& p = *this->Internals;
  std::copy(bounds, bounds + 6, p.bounds);
  p.aerial = up != nullptr;
  p.window->SetOffScreenRendering(1);
  p.window->SetSize(PictureSize, PictureSize);
  p.window->SetMultiSamples(8);
  p.window->AddRenderer(p.renderer);
  p.renderer->SetBackground(0, 0, 0);

  // The colours already are the lighting: shown as they are, unlit, as ParaView's Elements
  // representation shows them (Map Scalars off).
  p.elementsMapper->SetInputData(p.elements);
  p.elementsMapper->SetScalarModeToUsePointFieldData();
  p.elementsMapper->SelectColorArray("Color");
  p.elementsMapper->SetColorModeToDirectScalars();
  p.elementsMapper->ScalarVisibilityOn();
  p.elementsActor->SetMapper(p.elementsMapper);
  p.elementsActor->GetProperty()->LightingOff();
  p.renderer->AddActor(p.elementsActor);

  p.lightMapper->SetInputData(p.light);
  p.lightMapper->ScalarVisibilityOff();
  p.lightActor->SetMapper(p.lightMapper);
  p.lightActor->GetProperty()->SetColor(LightColor[0], LightColor[1], LightColor[2]);
  p.lightActor->GetProperty()->LightingOff();
  p.renderer->AddActor(p.lightActor);

  // Look along +z at the bounding box, from far enough for its front face to fill the view.
  const double centre[3] = { 0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]),
    0.5 * (bounds[4] + bounds[5]) };
  const double halfSize = 0.5 * std::max(bounds[1] - bounds[0], bounds[3] - bounds[2]);
  const double distance =
    halfSize / std::tan(0.5 * ViewAngleDegrees * M_PI / 180.0) + (centre[2] - bounds[4]);
  vtkCamera* camera = p.renderer->GetActiveCamera();
  camera->SetViewAngle(ViewAngleDegrees);
  camera->SetFocalPoint(centre);
  camera->SetPosition(centre[0], centre[1], centre[2] - std::max(distance, 1e-6));
  camera->SetViewUp(0, 1, 0);
  camera->GetPosition(p.view.position);
  p.view.viewAngle = ViewAngleDegrees;
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
    double b[3] = { u[1] * a[2] - u[2] * a[1], u[2] * a[0] - u[0] * a[2],
      u[0] * a[1] - u[1] * a[0] };
    const double bn = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    double c[3] = { u[1] * b[2] - u[2] * b[1], u[2] * b[0] - u[0] * b[2],
      u[0] * b[1] - u[1] * b[0] };
    const double radius = 0.5 *
      std::sqrt((bounds[1] - bounds[0]) * (bounds[1] - bounds[0]) +
        (bounds[3] - bounds[2]) * (bounds[3] - bounds[2]) +
        (bounds[5] - bounds[4]) * (bounds[5] - bounds[4]));
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

void FrameRenderer::sampleLighting(vtkPolyData* elements)
{
  Pipeline& p = *this->Internals;
  if (p.aerial || p.chosen || !elements || elements->GetNumberOfCells() == 0)
  {
    return;
  }
  vtkCellData* data = elements->GetCellData();
  vtkDataArray* frontArray = data->GetArray("RadiosityFront");
  vtkDataArray* backArray = data->GetArray("RadiosityBack");
  if (!frontArray || !backArray)
  {
    // One-sided surfaces: back faces absorb everything, and Radiosity is the front's.
    frontArray = data->GetArray("Radiosity");
    backArray = nullptr;
  }
  // A lamp of the scene's own (its Emission) outshines what it lights by orders of magnitude:
  // only the light a side receives counts.
  vtkDataArray* emittedArray = data->GetArray("EmittedRadiosity");
  const vtkIdType cells = elements->GetNumberOfCells();
  if (!frontArray || frontArray->GetNumberOfTuples() != cells ||
    frontArray->GetNumberOfComponents() != 3 ||
    (backArray &&
      (backArray->GetNumberOfTuples() != cells || backArray->GetNumberOfComponents() != 3)))
  {
    return;
  }
  if (p.mesh->GetNumberOfCells() == 0)
  {
    p.mesh->SetPoints(elements->GetPoints());
    p.mesh->SetPolys(elements->GetPolys());
    p.front.assign(static_cast<std::size_t>(cells), 0.0);
    p.back.assign(static_cast<std::size_t>(cells), 0.0);
  }
  else if (p.mesh->GetNumberOfCells() != cells)
  {
    return; // not the mesh of the frames sampled before
  }
  auto cellLuminance = [](vtkDataArray* array, vtkIdType c)
  {
    return mlr::luminance(
      mlr::Rgb(array->GetComponent(c, 0), array->GetComponent(c, 1), array->GetComponent(c, 2)));
  };
  const bool emission = emittedArray && emittedArray->GetNumberOfTuples() == cells &&
    emittedArray->GetNumberOfComponents() == 3;
  for (vtkIdType c = 0; c < cells; ++c)
  {
    const auto k = static_cast<std::size_t>(c);
    // Emission leaves the front only.
    p.front[k] += std::max(
      0.0, cellLuminance(frontArray, c) - (emission ? cellLuminance(emittedArray, c) : 0.0));
    p.back[k] += backArray ? cellLuminance(backArray, c) : 0.0;
  }
}

const FrameRenderer::View& FrameRenderer::chooseView()
{
  Pipeline& p = *this->Internals;
  if (p.chosen)
  {
    return p.view;
  }
  p.chosen = true;
  if (p.aerial || p.mesh->GetNumberOfCells() == 0)
  {
    return p.view;
  }
  vtkNew<vtkStaticCellLocator> locator;
  locator->SetDataSet(p.mesh);
  locator->BuildLocator();
  const double* b = p.bounds;
  const double diagonal = std::sqrt(
    (b[1] - b[0]) * (b[1] - b[0]) + (b[3] - b[2]) * (b[3] - b[2]) + (b[5] - b[4]) * (b[5] - b[4]));
  if (!(diagonal > 0))
  {
    return p.view;
  }
  const double outside[3] = { p.view.position[0], p.view.position[1], p.view.position[2] };
  p.view.litOutside = p.litShare(locator, outside, p.view.viewAngle);
  if (p.view.litOutside >= OutsideEnough)
  {
    return p.view;
  }
  // Candidates just past each surface the axis crosses: a room's near wall, then what stands
  // in the room. The nearest that sees almost as many lit sides as the best is kept, the
  // widest view of the room.
  const double halfSize = 0.5 * std::max(b[1] - b[0], b[3] - b[2]);
  const double end[3] = { outside[0], outside[1], b[5] + diagonal };
  const double tolerance = 1e-9 * diagonal;
  double from[3] = { outside[0], outside[1], outside[2] };
  std::vector<View> candidates;
  for (int k = 0; k < InsideCandidates; ++k)
  {
    double t = 0, hit[3], pcoords[3];
    int subId = 0;
    vtkIdType cell = -1;
    if (!locator->IntersectWithLine(from, end, tolerance, t, hit, pcoords, subId, cell) || cell < 0)
    {
      break;
    }
    // Past the surface by 2% of the depth, or half the way to the next one when closer.
    double next[3] = { hit[0], hit[1], hit[2] + 1e-6 * diagonal };
    double nextHit[3], nextT = 0;
    vtkIdType nextCell = -1;
    const double gap =
      locator->IntersectWithLine(next, end, tolerance, nextT, nextHit, pcoords, subId, nextCell) &&
        nextCell >= 0
      ? nextHit[2] - hit[2]
      : b[5] - hit[2];
    const double step = std::min(0.02 * (b[5] - b[4]), 0.5 * gap);
    if (step > 1e-6 * diagonal)
    {
      const double eye[3] = { hit[0], hit[1], hit[2] + step };
      // Wide enough for the far side of the bounds to take about two thirds of the picture.
      const double depth = std::max(b[5] - eye[2], 1e-3 * diagonal);
      const double angle = std::clamp(
        2 * std::atan(halfSize / (0.7 * depth)) * 180 / M_PI, ViewAngleDegrees, WidestViewDegrees);
      View candidate = p.view;
      candidate.litInside = p.litShare(locator, eye, angle);
      std::copy(eye, eye + 3, candidate.position);
      candidate.viewAngle = angle;
      candidates.push_back(candidate);
    }
    from[2] = hit[2] + std::max(step, 1e-6 * diagonal);
  }
  View best = p.view;
  for (const View& candidate : candidates)
  {
    best.litInside = std::max(best.litInside, candidate.litInside);
  }
  for (const View& candidate : candidates)
  {
    if (candidate.litInside >= NearlyTheBest * best.litInside)
    {
      best = candidate;
      break;
    }
  }
  if (best.litInside >= MinimumLit && best.litInside >= InsideGain * p.view.litOutside)
  {
    best.inside = true;
    p.view = best;
    vtkCamera* camera = p.renderer->GetActiveCamera();
    camera->SetPosition(best.position);
    camera->SetFocalPoint(best.position[0], best.position[1], best.position[2] + 1);
    camera->SetViewUp(0, 1, 0);
    camera->SetViewAngle(best.viewAngle);
  }
  else
  {
    p.view.litInside = best.litInside;
  }
  return p.view;
}

void FrameRenderer::render(
  vtkPolyData* elements, vtkPolyData* light, const std::filesystem::path& png)
{
  Pipeline& p = *this->Internals;
  this->chooseView();
  p.elements->ShallowCopy(elements);
  p.light->ShallowCopy(light);
  p.renderer->ResetCameraClippingRange();
  p.window->Render();

  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(p.window);
  grab->ReadFrontBufferOff();
  grab->ShouldRerenderOff(); // rendered just above: a second render cost as much again
  vtkNew<vtkPNGWriter> writer;
  writer->SetInputConnection(grab->GetOutputPort());
  writer->WriteToMemoryOn();
  writer->Write();
  vtkUnsignedCharArray* bytes = writer->GetResult();
  if (writer->GetErrorCode() != 0 || !bytes)
  {
    throw std::runtime_error("cannot encode the picture '" + png.string() + "'");
  }
  writeFileBytes(png,
    std::string(reinterpret_cast<const char*>(bytes->GetPointer(0)),
      static_cast<std::size_t>(bytes->GetNumberOfValues())),
    "the picture");
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
