"""Shared by the parallel tests' pvbatch and pvpython scripts: one output mesh as arrays."""
import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy


def record_mesh(results, key, data):
    """Puts the triangles of `data` into `results` under `key`: the cell count (key_cells),
    the corners (key_corners, cells x 3 x 3), every cell array (key_cell_NAME) and every point
    array per cell corner (key_corner_NAME), so that cells can be matched across ranks."""
    cells = data.GetNumberOfCells()
    results[f"{key}_cells"] = np.array(cells)
    if cells == 0:
        return
    points = vtk_to_numpy(data.GetPoints().GetData()).astype(np.float64)
    triangles = vtk_to_numpy(data.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    results[f"{key}_corners"] = points[triangles]
    for i in range(data.GetCellData().GetNumberOfArrays()):
        array = data.GetCellData().GetArray(i)
        if array is not None:
            results[f"{key}_cell_{array.GetName()}"] = vtk_to_numpy(array)
    for i in range(data.GetPointData().GetNumberOfArrays()):
        array = data.GetPointData().GetArray(i)
        if array is not None:
            results[f"{key}_corner_{array.GetName()}"] = vtk_to_numpy(array)[triangles]
