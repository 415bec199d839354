#include "vtkSunPathSource.h"

#include "Error.h"
#include "SunPath.h"

#include "vtkCellArray.h"
#include "vtkDoubleArray.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

vtkStandardNewMacro(vtkSunPathSource);

//------------------------------------------------------------------------------
vtkSunPathSource::vtkSunPathSource()
  : Latitude(48.85)
  , Longitude(2.35)
  , Year(2024)
  , Month(6)
  , Day(21)
  , StartTime(6)
  , EndTime(20)
  , StepMinutes(15)
  , TimeZone(0)
{
  this->North[0] = 0;
  this->North[1] = 1;
  this->North[2] = 0;
  this->Up[0] = 0;
  this->Up[1] = 0;
  this->Up[2] = 1;
  this->SetNumberOfInputPorts(0);
}

//------------------------------------------------------------------------------
int vtkSunPathSource::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  output->Initialize();
  mlr::SunPathRequest request;
  request.latitude = this->Latitude;
  request.longitude = this->Longitude;
  request.year = this->Year;
  request.month = this->Month;
  request.day = this->Day;
  request.startHour = this->StartTime;
  request.endHour = this->EndTime;
  request.stepMinutes = this->StepMinutes;
  request.timeZoneHours = this->TimeZone;
  request.north = { this->North[0], this->North[1], this->North[2] };
  request.up = { this->Up[0], this->Up[1], this->Up[2] };
  std::vector<mlr::SunPosition> path;
  try
  {
    path = mlr::sunPath(request);
  }
  catch (const mlr::Error& e)
  {
    vtkErrorMacro(<< e.what());
    return 0;
  }

  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> time, azimuth, elevation, power;
  time->SetName("Time");
  azimuth->SetName("SunAzimuth");
  elevation->SetName("SunElevation");
  power->SetName("Power");
  vtkNew<vtkCellArray> line;
  line->InsertNextCell(static_cast<vtkIdType>(path.size()));
  for (const mlr::SunPosition& p : path)
  {
    line->InsertCellPoint(points->InsertNextPoint(p.direction.x, p.direction.y, p.direction.z));
    time->InsertNextValue(p.clockHours);
    azimuth->InsertNextValue(p.azimuthDegrees);
    elevation->InsertNextValue(p.elevationDegrees);
    power->InsertNextValue(p.elevationDegrees > 0 ? 1.0 : 0.0);
  }
  output->SetPoints(points);
  output->SetLines(line);
  output->GetPointData()->AddArray(time);
  output->GetPointData()->AddArray(azimuth);
  output->GetPointData()->AddArray(elevation);
  output->GetPointData()->AddArray(power);
  return 1;
}

//------------------------------------------------------------------------------
void vtkSunPathSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Latitude: " << this->Latitude << " degrees\n";
  os << indent << "Longitude: " << this->Longitude << " degrees\n";
  os << indent << "Date: " << this->Year << "-" << this->Month << "-" << this->Day << "\n";
  os << indent << "StartTime: " << this->StartTime << " h\n";
  os << indent << "EndTime: " << this->EndTime << " h\n";
  os << indent << "StepMinutes: " << this->StepMinutes << "\n";
  os << indent << "TimeZone: " << this->TimeZone << " h from UTC\n";
  os << indent << "North: (" << this->North[0] << ", " << this->North[1] << ", " << this->North[2]
     << ")\n";
  os << indent << "Up: (" << this->Up[0] << ", " << this->Up[1] << ", " << this->Up[2] << ")\n";
}
