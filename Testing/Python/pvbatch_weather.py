"""vtkSunPathSource reads a weather file inside pvbatch (ParaView's own interpreter), and the
filter is lit by its hours there. Run as:
    pvbatch --force-offscreen-rendering pvbatch_weather.py
with PYTHONPATH set to the build's Python folder and MLR_DATA_DIR to Data/. Exits non-zero
on failure."""
import os
import sys

from vtkmodules.vtkFiltersSources import vtkPlaneSource

from movinglightradiosity import vtkMovingLightRadiosity, vtkSunPathSource

source = vtkSunPathSource()
source.SetWeatherFile(os.path.join(os.environ["MLR_DATA_DIR"], "paris_synthetic.epw"))
source.SetFirstDate(3, 20)
source.SetLastDate(3, 20)
source.SetHours(11, 13)
source.Update()
path = source.GetOutput()
failures = []
if path.GetNumberOfPoints() != 3:
    failures.append(f"{path.GetNumberOfPoints()} frames for the hours 11 to 13 of a day")
for name in ("Time", "DayOfYear", "ClockHour", "DirectNormalIrradiance", "SkyDiffuseHorizontal"):
    if path.GetPointData().GetArray(name) is None:
        failures.append(f"no point array {name}")
if not failures and path.GetPointData().GetArray("DayOfYear").GetValue(0) != 79:
    failures.append("March 20 is not day 79")

ground = vtkPlaneSource()
radiosity = vtkMovingLightRadiosity()
radiosity.SetInputConnection(0, ground.GetOutputPort())
radiosity.SetInputConnection(2, source.GetOutputPort())
radiosity.SetLightTypeToDirectional()
radiosity.SetSkyModel(vtkMovingLightRadiosity.PEREZ_SKY)
radiosity.SetNumberOfPaths(5000)
radiosity.SetPatchSize(0.5)
if not radiosity.UpdateTimeStep(78 * 24 + 12.0):
    failures.append("the update at March 20 12:00 failed")
else:
    array = radiosity.GetOutput(0).GetCellData().GetArray("Irradiance")
    if array is None or array.GetRange(-1)[1] <= 0:
        failures.append("no Irradiance from the weather file's sun and sky")

print("\n".join(failures) if failures else "pvbatch: vtkSunPathSource with WeatherFile OK")
sys.exit(1 if failures else 0)
