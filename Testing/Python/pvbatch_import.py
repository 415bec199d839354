"""The Python package loads inside pvbatch (ParaView's own interpreter) and the filter runs
there on ParaView's VTK. Run as:  pvbatch --force-offscreen-rendering pvbatch_import.py
with PYTHONPATH set to the build's Python folder. Exits non-zero on failure."""
import sys

from vtkmodules.vtkFiltersSources import vtkCubeSource, vtkPlaneSource

from movinglightradiosity import vtkMovingLightRadiosity

box = vtkCubeSource()  # outward normals: the lit side of its walls is the back side
box.SetBounds(0, 1, 0, 1, 0, 1)
light = vtkPlaneSource()
light.SetOrigin(0.4, 0.4, 0.9)
light.SetPoint1(0.4, 0.6, 0.9)  # normal = (P1 - O) x (P2 - O) = -z
light.SetPoint2(0.6, 0.4, 0.9)

radiosity = vtkMovingLightRadiosity()
radiosity.SetInputConnection(0, box.GetOutputPort())
radiosity.SetInputConnection(1, light.GetOutputPort())
radiosity.SetPathStart(0.3, 0.3, 0.9)
radiosity.SetPathEnd(0.7, 0.7, 0.9)
radiosity.SetNumberOfPositions(3)
radiosity.SetNumberOfPaths(20000)
radiosity.SetPatchSize(0.2)

failures = []
for t in (0.0, 2.0, 1.0):
    if not radiosity.UpdateTimeStep(t):
        failures.append(f"update at time {t} failed")
        continue
    output = radiosity.GetOutput(0)
    shown = output.GetInformation().Get(output.DATA_TIME_STEP())
    if shown != t:
        failures.append(f"asked for time {t}, got {shown}")
    array = output.GetCellData().GetArray("Radiosity")
    if array is None or array.GetRange(-1)[1] <= 0:
        failures.append(f"no lit Radiosity at time {t}")
if radiosity.GetSolveCount() != 1:
    failures.append(f"{radiosity.GetSolveCount()} solves for one animation")

print("\n".join(failures) if failures else "pvbatch: vtkMovingLightRadiosity OK")
sys.exit(1 if failures else 0)
