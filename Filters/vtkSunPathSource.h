/**
 * @class   vtkSunPathSource
 * @brief   directions towards the sun over a day, as a Trajectory for a directional light
 *
 * vtkSunPathSource computes where the sun is, seen from a place on Earth on one day, every
 * StepMinutes from StartTime to EndTime (local clock time), with libnova's solar theory
 * (VSOP87). Its output is a polyline through one point per frame: the unit direction towards
 * the sun in scene coordinates, given the scene's North and Up. Connect it to the Trajectory
 * of vtkMovingLightRadiosity with LightType Directional.
 *
 * Point arrays: `Time` (the local clock time in hours: the frames' times), `SunAzimuth`
 * (degrees from north towards east), `SunElevation` (degrees above the horizon, without
 * refraction) and `Power` (1 with the sun above the horizon, 0 below: night frames are kept,
 * dark, so that the frames match the clock times).
 *
 * With a WeatherFile (an EnergyPlus weather file, .epw) the frames are instead the hours of
 * its year from FirstDate to LastDate and within Hours, with the sun at the file's place and
 * in its time zone at the middle of each hour; the hours with the sun below the horizon
 * there are left out unless IncludeNight. Latitude, Longitude, the date, the times and
 * TimeZone are then not used. `Time` is the hour of the year at the start of each hour (0 is
 * January 1 00:00 to 01:00; after a selection that wraps over the new year, January's hours
 * count on from the year's last, 8760 and up), and the point arrays also hold what
 * vtkMovingLightRadiosity reads per frame: `DirectNormalIrradiance` and
 * `SkyDiffuseHorizontal` (W/m^2, the file's hourly means), and `GlobalHorizontalIrradiance`
 * (W/m^2, the file's, NaN where it is missing), `ClockHour` (0 to 23, the clock time the
 * hour starts at) beside them. Both modes give `DayOfYear` (1 to 366), the date of the Perez
 * sky's extraterrestrial irradiance, and the field data `TimeStepHours`, the hours a frame
 * stands for (StepMinutes / 60, or 1 for a weather file's hour), which the filter's
 * `DirectSunHours` counts.
 *
 * Bad input (a latitude outside +-90, a date that does not exist, an end before the start, a
 * north that is not horizontal, a weather file that cannot be read, naming its line, ...)
 * gives an error naming what to fix and an empty output.
 */

#ifndef vtkSunPathSource_h
#define vtkSunPathSource_h

#include "MovingLightRadiosityFiltersModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

#include <string> // For WeatherFile

class MOVINGLIGHTRADIOSITYFILTERS_EXPORT vtkSunPathSource : public vtkPolyDataAlgorithm
{
public:
  static vtkSunPathSource* New();
  vtkTypeMacro(vtkSunPathSource, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Latitude (degrees, north positive, -90 to 90) and longitude (degrees, east positive,
   * -180 to 180) of the place. Defaults 48.85, 2.35 (Paris).
   */
  vtkSetMacro(Latitude, double);
  vtkGetMacro(Latitude, double);
  vtkSetMacro(Longitude, double);
  vtkGetMacro(Longitude, double);
  ///@}

  ///@{
  /**
   * The day: year, month (1-12) and day of the month. Default 2024-06-21.
   */
  vtkSetMacro(Year, int);
  vtkGetMacro(Year, int);
  vtkSetMacro(Month, int);
  vtkGetMacro(Month, int);
  vtkSetMacro(Day, int);
  vtkGetMacro(Day, int);
  ///@}

  ///@{
  /**
   * First and last local clock times, in hours (6.5 is 06:30), and the minutes between two
   * frames. Defaults 6, 20 and 15.
   */
  vtkSetMacro(StartTime, double);
  vtkGetMacro(StartTime, double);
  vtkSetMacro(EndTime, double);
  vtkGetMacro(EndTime, double);
  vtkSetMacro(StepMinutes, double);
  vtkGetMacro(StepMinutes, double);
  ///@}

  ///@{
  /**
   * The local clock's offset from UTC, in hours (2 for CEST). Default 0 (UTC).
   */
  vtkSetMacro(TimeZone, double);
  vtkGetMacro(TimeZone, double);
  ///@}

  ///@{
  /**
   * The scene's north (horizontal) and zenith directions. Defaults 0,1,0 and 0,0,1.
   */
  vtkSetVector3Macro(North, double);
  vtkGetVector3Macro(North, double);
  vtkSetVector3Macro(Up, double);
  vtkGetVector3Macro(Up, double);
  ///@}

  ///@{
  /**
   * An EnergyPlus weather file (.epw) whose hours become the frames instead of one day of
   * the place above. Default empty (none).
   */
  vtkSetStdStringFromCharMacro(WeatherFile);
  vtkGetCharFromStdStringMacro(WeatherFile);
  ///@}

  ///@{
  /**
   * The first and last days of the weather file's hours, each (month, day), both included;
   * a last day before the first wraps over the new year. Defaults (1, 1) and (12, 31).
   */
  vtkSetVector2Macro(FirstDate, int);
  vtkGetVector2Macro(FirstDate, int);
  vtkSetVector2Macro(LastDate, int);
  vtkGetVector2Macro(LastDate, int);
  ///@}

  ///@{
  /**
   * The first and last clock hours of each day of the weather file, 0 to 23, each naming
   * the hour that starts then: (8, 16) is 08:00 to 17:00. Default (0, 23).
   */
  vtkSetVector2Macro(Hours, int);
  vtkGetVector2Macro(Hours, int);
  ///@}

  ///@{
  /**
   * Keep the weather file's hours whose sun is below the horizon at their middle (dark for
   * the sun, Power 0). Default off.
   */
  vtkSetMacro(IncludeNight, bool);
  vtkGetMacro(IncludeNight, bool);
  vtkBooleanMacro(IncludeNight, bool);
  ///@}

protected:
  vtkSunPathSource();
  ~vtkSunPathSource() override = default;

  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;

  double Latitude;
  double Longitude;
  int Year;
  int Month;
  int Day;
  double StartTime;
  double EndTime;
  double StepMinutes;
  double TimeZone;
  double North[3];
  double Up[3];
  std::string WeatherFile;
  int FirstDate[2];
  int LastDate[2];
  int Hours[2];
  bool IncludeNight;

private:
  vtkSunPathSource(const vtkSunPathSource&) = delete;
  void operator=(const vtkSunPathSource&) = delete;
};

#endif
