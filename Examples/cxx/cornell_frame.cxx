// The Cornell box's light moving along its trajectory: one solve for all 30 frames, then
// frame 15's elements and their mean radiosity. Argument: the folder of the Data files.
#include "vtkMovingLightRadiosity.h"

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include <iostream>
#include <string>

int main(int argc, char* argv[])
{
  const std::string data = argc > 1 ? argv[1] : "Data";
  vtkNew<vtkXMLPolyDataReader> scene, light, trajectory;
  scene->SetFileName((data + "/cornell_box.vtp").c_str());
  light->SetFileName((data + "/cornell_light.vtp").c_str());
  trajectory->SetFileName((data + "/cornell_trajectory.vtp").c_str());
  vtkNew<vtkMovingLightRadiosity> radiosity;
  radiosity->SetSceneConnection(scene->GetOutputPort());
  radiosity->SetLightConnection(light->GetOutputPort());
  radiosity->SetTrajectoryConnection(trajectory->GetOutputPort());
  if (argc > 2)
  {
    radiosity->SetNumberOfPaths(std::stoll(argv[2]));
  }
  if (!radiosity->UpdateTimeStep(15)) // solves all 30 frames once
  {
    return 1;
  }
  vtkPolyData* elements = radiosity->GetOutput(vtkMovingLightRadiosity::ELEMENTS_PORT);
  vtkDataArray* b = elements->GetCellData()->GetArray("Radiosity");
  double sum = 0;
  for (vtkIdType c = 0; c < b->GetNumberOfTuples(); ++c)
  {
    sum += b->GetComponent(c, 0);
  }
  std::cout << elements->GetNumberOfCells() << " elements, mean red radiosity "
            << sum / static_cast<double>(b->GetNumberOfTuples()) << " W/m^2 in frame 15\n";
  return 0;
}
