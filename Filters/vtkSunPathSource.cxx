#include "vtkSunPathSource.h"

#include "Error.h"
#include "SunPath.h"
#include "WeatherFile.h"

#include "vtkCellArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
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
  , IncludeNight(false)
{
  this->FirstDate[0] = 1;
  this->FirstDate[1] = 1;
  this->LastDate[0] = 12;
  this->LastDate[1] = 31;
  this->Hours[0] = 0;
  this->Hours[1] = 23;
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
  std::vector<mlr::SunPosition> path;
  std::vector<mlr::WeatherFrame> hours;
  int dayOfYear = 0;
  try
  {
    if (!this->WeatherFile.empty())
    {
      mlr::WeatherSelection selection;
      selection.firstMonth = this->FirstDate[0];
      selection.firstDay = this->FirstDate[1];
      selection.lastMonth = this->LastDate[0];
      selection.lastDay = this->LastDate[1];
      selection.firstHour = this->Hours[0];
      selection.lastHour = this->Hours[1];
      selection.includeNight = this->IncludeNight;
      selection.north = { this->North[0], this->North[1], this->North[2] };
      selection.up = { this->Up[0], this->Up[1], this->Up[2] };
      const mlr::WeatherFile file = mlr::readWeatherFile(this->WeatherFile);
      hours = mlr::weatherFrames(file, selection);
      for (const std::string& warning : { mlr::irradianceClosureWarning(file, hours),
             mlr::directNormalAboveTheSunWarning(file, hours) })
      {
        if (!warning.empty())
        {
          vtkWarningMacro(<< warning);
        }
      }
      for (const mlr::WeatherFrame& h : hours)
      {
        path.push_back(h.sun);
      }
    }
    else
    {
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
      path = mlr::sunPath(request);
      dayOfYear = mlr::dayOfYear(this->Year, this->Month, this->Day);
      const std::string warning = mlr::timeZoneWarning(this->Longitude, this->TimeZone);
      if (!warning.empty())
      {
        vtkWarningMacro(<< warning);
      }
    }
  }
  catch (const mlr::Error& e)
  {
    vtkErrorMacro(<< e.what());
    return 0;
  }

  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> time, azimuth, elevation, power, days;
  time->SetName("Time");
  azimuth->SetName("SunAzimuth");
  elevation->SetName("SunElevation");
  power->SetName("Power");
  days->SetName("DayOfYear");
  vtkNew<vtkCellArray> line;
  line->InsertNextCell(static_cast<vtkIdType>(path.size()));
  for (std::size_t k = 0; k < path.size(); ++k)
  {
    const mlr::SunPosition& p = path[k];
    line->InsertCellPoint(points->InsertNextPoint(p.direction.x, p.direction.y, p.direction.z));
    time->InsertNextValue(hours.empty() ? p.clockHours : hours[k].seriesHour);
    azimuth->InsertNextValue(p.azimuthDegrees);
    elevation->InsertNextValue(p.elevationDegrees);
    power->InsertNextValue(p.elevationDegrees > 0 ? 1.0 : 0.0);
    days->InsertNextValue(hours.empty() ? dayOfYear : hours[k].dayOfYear);
  }
  output->SetPoints(points);
  output->SetLines(line);
  vtkPointData* data = output->GetPointData();
  for (vtkDoubleArray* array :
    { time.Get(), azimuth.Get(), elevation.Get(), power.Get(), days.Get() })
  {
    data->AddArray(array);
  }
  // How long a frame lasts, for the filter's DirectSunHours: the frames' times need not be
  // evenly spaced (a weather file's chosen hours skip the nights, or all but noon).
  vtkNew<vtkDoubleArray> stepHours;
  stepHours->SetName("TimeStepHours");
  stepHours->InsertNextValue(hours.empty() ? this->StepMinutes / 60.0 : 1.0);
  output->GetFieldData()->AddArray(stepHours);
  if (!hours.empty())
  {
    const std::pair<const char*, double mlr::WeatherFrame::*> perHour[] = {
      { "DirectNormalIrradiance", &mlr::WeatherFrame::directNormal },
      { "SkyDiffuseHorizontal", &mlr::WeatherFrame::diffuseHorizontal },
      { "GlobalHorizontalIrradiance", &mlr::WeatherFrame::globalHorizontal },
    };
    for (const auto& [name, member] : perHour)
    {
      vtkNew<vtkDoubleArray> array;
      array->SetName(name);
      for (const mlr::WeatherFrame& h : hours)
      {
        array->InsertNextValue(h.*member);
      }
      data->AddArray(array);
    }
    vtkNew<vtkDoubleArray> clock;
    clock->SetName("ClockHour");
    for (const mlr::WeatherFrame& h : hours)
    {
      clock->InsertNextValue(h.clockHour);
    }
    data->AddArray(clock);
  }
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
  os << indent << "WeatherFile: " << (this->WeatherFile.empty() ? "(none)" : this->WeatherFile)
     << "\n";
  os << indent << "FirstDate: " << this->FirstDate[0] << "-" << this->FirstDate[1] << "\n";
  os << indent << "LastDate: " << this->LastDate[0] << "-" << this->LastDate[1] << "\n";
  os << indent << "Hours: " << this->Hours[0] << " to " << this->Hours[1] << "\n";
  os << indent << "IncludeNight: " << (this->IncludeNight ? "on" : "off") << "\n";
}
