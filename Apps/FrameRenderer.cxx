#include "FrameRenderer.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCellData.h"
#include "vtkCellDataToPointData.h"
#include "vtkDataArray.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkPolyDataNormals.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkWindowToImageFilter.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
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
  vtkNew<vtkCellDataToPointData> smooth;
  vtkNew<vtkPolyData> shown;
  vtkNew<vtkPolyDataMapper> sceneMapper;
  vtkNew<vtkActor> sceneActor;
  vtkNew<vtkActor> lightActor;
  double exposure = 1.0;
};

FrameRenderer::FrameRenderer(vtkPolyData* light, const double bounds[6])
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
  p.smooth->SetInputConnection(p.creases->GetOutputPort());
  p.smooth->ProcessAllArraysOff();
  p.smooth->AddCellDataArray("Radiosity");
  p.sceneMapper->SetInputData(p.shown);
  p.sceneMapper->SetScalarModeToUsePointData();
  p.sceneMapper->SetColorModeToDirectScalars();
  p.sceneActor->SetMapper(p.sceneMapper);
  p.sceneActor->GetProperty()->LightingOff();
  p.renderer->AddActor(p.sceneActor);

  vtkNew<vtkPolyDataMapper> lightMapper;
  lightMapper->SetInputData(light);
  lightMapper->ScalarVisibilityOff();
  p.lightActor->SetMapper(lightMapper);
  p.lightActor->GetProperty()->SetColor(1, 1, 1);
  p.lightActor->GetProperty()->LightingOff();
  p.renderer->AddActor(p.lightActor);

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
  p.scene->ShallowCopy(elements);
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
  vtkNew<vtkPNGWriter> writer;
  writer->SetInputConnection(grab->GetOutputPort());
  writer->SetFileName(png.string().c_str());
  writer->Write();
  if (writer->GetErrorCode() != 0)
  {
    throw std::runtime_error("cannot write the picture '" + png.string() + "'");
  }
}

} // namespace mlr::cli
