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
 * Bad input (a latitude outside +-90, a date that does not exist, an end before the start, a
 * north that is not horizontal, ...) gives an error naming what to fix and an empty output.
 */

#ifndef vtkSunPathSource_h
#define vtkSunPathSource_h

#include "MovingLightRadiosityFiltersModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

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

private:
  vtkSunPathSource(const vtkSunPathSource&) = delete;
  void operator=(const vtkSunPathSource&) = delete;
};

#endif
