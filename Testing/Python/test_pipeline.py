"""The filter in a plain VTK pipeline from Python: sources and readers in, a .pvd + .vtu time
series out through VTK's writers, read back with VTK's readers.

Run by ctest with PYTHONPATH set to the build's Python folder (see CMakeLists.txt), or by hand:
    PYTHONPATH=build/lib/python3/dist-packages /usr/bin/python3 -m pytest Testing/Python
"""
import os
import sys
import xml.etree.ElementTree as ElementTree

import numpy
import pytest

from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline
from vtkmodules.vtkFiltersCore import vtkAppendFilter
from vtkmodules.vtkFiltersSources import vtkLineSource, vtkPlaneSource
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLUnstructuredGridReader
from paraview.modules.vtkPVVTKExtensionsIOCore import vtkPVDReader, vtkXMLPVDWriter

from movinglightradiosity import vtkMovingLightRadiosity

sys.path.insert(0, os.path.join(os.path.dirname(__file__), os.pardir, "Support"))
from vtk_messages import recorded  # noqa: E402

DATA = os.environ.get("MLR_DATA_DIR",
                      os.path.join(os.path.dirname(__file__), os.pardir, os.pardir, "Data"))
FRAMES = 5
ELEMENT_ARRAYS = ("Radiosity", "DirectRadiosity", "IndirectRadiosity", "RadiosityFront",
                  "RadiosityBack", "Reflectance", "PatchId")


def field(data, name):
    array = data.GetFieldData().GetArray(name)
    assert array is not None, f"no field array {name}"
    return array.GetTuple(0) if array.GetNumberOfComponents() > 1 else array.GetValue(0)


@pytest.fixture(scope="module")
def pipeline():
    """Cornell box from the shipped .vtp, a plane source as light, a line as trajectory."""
    scene = vtkXMLPolyDataReader()
    scene.SetFileName(os.path.join(DATA, "cornell_box.vtp"))

    light = vtkPlaneSource()  # 0.13 x 0.105 m, just below the ceiling, facing down
    light.SetOrigin(0.213, 0.5478, 0.227)
    light.SetPoint1(0.343, 0.5478, 0.227)  # normal = (P1 - O) x (P2 - O) = -y
    light.SetPoint2(0.213, 0.5478, 0.332)

    trajectory = vtkLineSource()
    trajectory.SetPoint1(0.15, 0.5478, 0.15)
    trajectory.SetPoint2(0.40, 0.5478, 0.40)
    trajectory.SetResolution(FRAMES - 1)

    radiosity = vtkMovingLightRadiosity()
    radiosity.SetInputConnection(0, scene.GetOutputPort())
    radiosity.SetInputConnection(1, light.GetOutputPort())
    radiosity.SetInputConnection(2, trajectory.GetOutputPort())
    radiosity.SetNumberOfPaths(30000)
    radiosity.SetPatchSize(0.06)
    # The sources must outlive this fixture: the filter holds only their outputs.
    return {"scene": scene, "light": light, "trajectory": trajectory, "filter": radiosity}


def test_light_normal_faces_down(pipeline):
    pipeline["light"].Update()
    assert pipeline["light"].GetNormal()[1] == pytest.approx(-1.0)


def test_time_steps_match_the_trajectory(pipeline):
    radiosity = pipeline["filter"]
    radiosity.UpdateInformation()
    info = radiosity.GetOutputInformation(0)
    assert info.Get(vtkStreamingDemandDrivenPipeline.TIME_STEPS()) == tuple(
        float(i) for i in range(FRAMES))
    assert info.Get(vtkStreamingDemandDrivenPipeline.TIME_RANGE()) == (0.0, FRAMES - 1.0)


def test_stepping_through_time_solves_once(pipeline):
    radiosity = pipeline["filter"]
    line = pipeline["trajectory"]
    line.Update()
    totals = []
    for frame in list(range(FRAMES)) + [3, 1]:
        assert radiosity.UpdateTimeStep(float(frame))
        elements = radiosity.GetOutput(0)
        assert elements.GetInformation().Get(elements.DATA_TIME_STEP()) == frame
        assert field(elements, "FrameIndex") == frame
        assert field(elements, "LightPosition") == pytest.approx(
            line.GetOutput().GetPoint(frame))
        for name in ELEMENT_ARRAYS:
            assert elements.GetCellData().GetArray(name) is not None, name
        radiosity_range = elements.GetCellData().GetArray("Radiosity").GetRange(-1)
        assert radiosity_range[1] > 0
        totals.append(radiosity_range[1])
        patches = radiosity.GetOutput(1)
        assert patches.GetCellData().GetArray("Radiosity") is not None
        assert elements.GetNumberOfCells() == 4 * patches.GetNumberOfCells()
    assert radiosity.GetSolveCount() == 1
    assert field(radiosity.GetOutput(0), "SolveCount") == 1
    assert len(set(totals[:FRAMES])) == FRAMES  # every frame is its own


def test_property_change_solves_again(pipeline):
    radiosity = pipeline["filter"]
    radiosity.UpdateTimeStep(0.0)
    solves = radiosity.GetSolveCount()
    radiosity.SetSeed(radiosity.GetSeed() + 1)
    radiosity.UpdateTimeStep(0.0)
    assert radiosity.GetSolveCount() == solves + 1


def test_threads_and_exposure_keep_the_solve(pipeline):
    """The solution is the same bits for any thread count: changing the threads solved the
    whole animation again for nothing (QA)."""
    radiosity = pipeline["filter"]
    radiosity.UpdateTimeStep(0.0)
    solves = radiosity.GetSolveCount()
    before = vtk_to_numpy(radiosity.GetOutput(0).GetCellData().GetArray("Radiosity")).copy()
    radiosity.SetNumberOfThreads(1 if radiosity.GetNumberOfThreads() != 1 else 2)
    radiosity.SetExposure(radiosity.GetExposure() + 1)
    radiosity.UpdateTimeStep(0.0)
    assert radiosity.GetSolveCount() == solves
    assert numpy.array_equal(
        vtk_to_numpy(radiosity.GetOutput(0).GetCellData().GetArray("Radiosity")), before)
    # Under a TimeLimit the rounds run depend on the speed: the threads then solve again.
    radiosity.SetTargetRelativeError(0.5)
    radiosity.SetTimeLimit(600)
    radiosity.UpdateTimeStep(0.0)
    solves = radiosity.GetSolveCount()
    radiosity.SetNumberOfThreads(1 if radiosity.GetNumberOfThreads() != 1 else 2)
    radiosity.UpdateTimeStep(0.0)
    assert radiosity.GetSolveCount() == solves + 1
    # Back to the fixture's settings, solved, for the tests that follow.
    radiosity.SetTimeLimit(0)
    radiosity.SetTargetRelativeError(0)
    radiosity.UpdateTimeStep(0.0)


def test_properties_the_solve_does_not_use_keep_it(pipeline):
    """With a Trajectory connected the path's ends and positions wait unused, as SunIrradiance
    does for an area light and SensorRays without sensors: changing them solved the animation
    again for the same bits (QA; in ParaView, a drag of the path's widget by mistake)."""
    radiosity = pipeline["filter"]
    radiosity.UpdateTimeStep(0.0)
    solves = radiosity.GetSolveCount()
    before = vtk_to_numpy(radiosity.GetOutput(0).GetCellData().GetArray("Radiosity")).copy()
    radiosity.SetPathStart(0.3, 0.5, 0.3)
    radiosity.SetPathEnd([0.1, 0.5, 0.1])
    radiosity.SetNumberOfPositions(radiosity.GetNumberOfPositions() + 3)
    radiosity.SetSunIrradiance(radiosity.GetSunIrradiance() / 2)
    radiosity.SetSensorRays(radiosity.GetSensorRays() * 2)
    radiosity.UpdateTimeStep(1.0)
    radiosity.UpdateTimeStep(0.0)
    assert radiosity.GetSolveCount() == solves
    assert numpy.array_equal(
        vtk_to_numpy(radiosity.GetOutput(0).GetCellData().GetArray("Radiosity")), before)
    # Without the Trajectory the path is used: a change solves again.
    lone = vtkMovingLightRadiosity()
    lone.SetInputConnection(0, pipeline["scene"].GetOutputPort())
    lone.SetInputConnection(1, pipeline["light"].GetOutputPort())
    lone.SetNumberOfPaths(2000)
    lone.SetPatchSize(0.1)
    lone.SetPathStart(0.15, 0.5478, 0.15)
    lone.SetPathEnd(0.40, 0.5478, 0.40)
    lone.SetNumberOfPositions(2)
    lone.UpdateTimeStep(0.0)
    lone.SetPathEnd(0.35, 0.5478, 0.35)
    lone.UpdateTimeStep(0.0)
    assert lone.GetSolveCount() == 2


def test_pvd_series_written_and_read_back(pipeline, tmp_path):
    radiosity = pipeline["filter"]
    grid = vtkAppendFilter()  # polygons -> unstructured grid, for .vtu
    grid.SetInputConnection(radiosity.GetOutputPort(0))
    writer = vtkXMLPVDWriter()
    writer.SetInputConnection(grid.GetOutputPort())
    writer.SetFileName(str(tmp_path / "series.pvd"))
    writer.WriteAllTimeStepsOn()
    solves = radiosity.GetSolveCount()
    assert writer.Write()
    assert radiosity.GetSolveCount() == solves  # the writer's time requests hit the cache

    collection = ElementTree.parse(tmp_path / "series.pvd").getroot()
    datasets = collection.findall("./Collection/DataSet")
    assert [float(d.get("timestep")) for d in datasets] == [float(i) for i in range(FRAMES)]

    reader = vtkPVDReader()
    reader.SetFileName(str(tmp_path / "series.pvd"))
    reader.UpdateInformation()
    times = reader.GetOutputInformation(0).Get(vtkStreamingDemandDrivenPipeline.TIME_STEPS())
    assert times == tuple(float(i) for i in range(FRAMES))

    previous = None
    for frame, dataset in enumerate(datasets):
        piece = vtkXMLUnstructuredGridReader()
        piece.SetFileName(str(tmp_path / dataset.get("file")))
        piece.Update()
        grid_frame = piece.GetOutput()
        assert grid_frame.GetNumberOfCells() > 0
        for name in ELEMENT_ARRAYS:
            assert grid_frame.GetCellData().GetArray(name) is not None, name
        assert field(grid_frame, "FrameIndex") == frame
        values = grid_frame.GetCellData().GetArray("Radiosity").GetRange(-1)
        assert values != previous
        previous = values


def test_frames_per_chunk_solves_in_chunks_and_keeps_every_frame(pipeline):
    """FramesPerChunk from Python: 5 frames in chunks of 2 (three chunks), every time step
    served from the one solve, each frame's mean radiosity within the noise of one chunk's."""
    radiosity = pipeline["filter"]
    assert radiosity.GetFramesPerChunk() == 0
    radiosity.SetSeed(0)
    means = []
    for chunk in (0, 2):
        radiosity.SetFramesPerChunk(chunk)
        radiosity.Modified()
        solves = radiosity.GetSolveCount()
        frame_means = []
        for frame in range(FRAMES):
            assert radiosity.UpdateTimeStep(float(frame))
            elements = radiosity.GetOutput(0)
            assert field(elements, "Chunks") == (1 if chunk == 0 else 3)
            values = elements.GetCellData().GetArray("Radiosity")
            frame_means.append(sum(values.GetTuple(i)[0] for i in range(values.GetNumberOfTuples()))
                               / values.GetNumberOfTuples())
        assert radiosity.GetSolveCount() == solves + 1
        means.append(frame_means)
    # N = 30,000: a frame mean's relative standard error is about 1/sqrt(N), 0.6%; 5% is far out.
    for whole, chunked in zip(*means):
        assert chunked == pytest.approx(whole, rel=0.05)
    radiosity.SetFramesPerChunk(0)


def surface_area(data):
    """The summed area of the polygons (and 2D cells) of a data set."""
    return sum(data.GetCell(c).ComputeArea() for c in range(data.GetNumberOfCells())
               if data.GetCell(c).GetCellDimension() == 2)


def grey_plane(origin, point1, point2, reflectance=None):
    from vtkmodules.vtkCommonCore import vtkDoubleArray
    plane = vtkPlaneSource()
    plane.SetOrigin(*origin)
    plane.SetPoint1(*point1)
    plane.SetPoint2(*point2)
    plane.Update()
    data = plane.GetOutput()
    if reflectance is not None:
        array = vtkDoubleArray()
        array.SetName("Reflectance")
        array.InsertNextValue(reflectance)
        data.GetCellData().AddArray(array)
    return data


def reflectance_areas(elements):
    """The elements' area of each (grey) reflectance."""
    reflectance = elements.GetCellData().GetArray("Reflectance")
    areas = {}
    for c in range(elements.GetNumberOfCells()):
        rho = round(reflectance.GetTuple(c)[0], 6)
        areas[rho] = areas.get(rho, 0.0) + elements.GetCell(c).ComputeArea()
    return areas


def lit(scene, paths=4000):
    """The Elements output of the scene under the sun straight above, and the warnings."""
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(scene)
    radiosity.SetLightTypeToDirectional()
    radiosity.SetPathStart(0, 0, 1)
    radiosity.SetPathEnd(0, 0, 1)
    radiosity.SetNumberOfPositions(1)
    radiosity.SetNumberOfPaths(paths)
    radiosity.SetPatchSize(0.25)
    radiosity.SetNumberOfThreads(2)
    radiosity.SetErrorBatches(1)
    messages = {event: recorded(radiosity, event) for event in ("ErrorEvent", "WarningEvent")}
    radiosity.Update()
    return radiosity.GetOutput(0), messages


def test_any_data_set_or_multiblock_gives_its_surface():
    from vtkmodules.vtkCommonDataModel import vtkImageData, vtkMultiBlockDataSet, vtkTable
    # A unit voxel (an image of 2 x 2 x 2 points): its surface is the six faces of its cell.
    voxel = vtkImageData()
    voxel.SetDimensions(2, 2, 2)
    elements, messages = lit(voxel)
    assert not messages["ErrorEvent"], messages
    assert surface_area(elements) == pytest.approx(6.0, rel=1e-9)

    # Two blocks of different reflectances, one of them an unstructured grid, keep them.
    floor = grey_plane((0, 0, 0), (1, 0, 0), (0, 1, 0), 0.2)
    wall = vtkAppendFilter()
    wall.AddInputData(grey_plane((0, 0, 0), (0, 1, 0), (0, 0, 2), 0.7))
    wall.Update()
    blocks = vtkMultiBlockDataSet()
    blocks.SetBlock(0, floor)
    blocks.SetBlock(1, wall.GetOutput())
    elements, messages = lit(blocks)
    assert not messages["ErrorEvent"], messages
    areas = reflectance_areas(elements)
    assert sorted(areas) == [0.2, 0.7]
    assert areas[0.2] == pytest.approx(1.0, rel=1e-9)
    assert areas[0.7] == pytest.approx(2.0, rel=1e-9)

    # An array of another type on each block is dropped too, with a warning naming it.
    from vtkmodules.vtkCommonCore import vtkIntArray, vtkLongLongArray
    for block, kind in ((0, vtkIntArray), (1, vtkLongLongArray)):
        zone = kind()
        zone.SetName("Zone")
        zone.SetNumberOfTuples(blocks.GetBlock(block).GetNumberOfCells())
        zone.Fill(block)
        blocks.GetBlock(block).GetCellData().AddArray(zone)
    elements, messages = lit(blocks)
    assert any("cell array 'Zone' is on every block, but not of one type and number of "
               "components, so it is dropped" in w for w in messages["WarningEvent"]), messages

    # A block without the Reflectance array takes the default grey 0.5, with a warning naming
    # it; the other keeps its own (dropping the array greyed the whole scene: QA).
    blocks.SetBlock(1, grey_plane((0, 0, 0), (0, 1, 0), (0, 0, 2)))
    elements, messages = lit(blocks)
    assert any("cell array 'Reflectance' is on 1 of its 2 blocks with cells: the block "
               "'block 1' without it takes 0.5" in w for w in messages["WarningEvent"]), messages
    areas = reflectance_areas(elements)
    assert sorted(areas) == [0.2, 0.5]
    assert areas[0.2] == pytest.approx(1.0, rel=1e-9)
    assert areas[0.5] == pytest.approx(2.0, rel=1e-9)

    # A table has no surface: the error says what to give.
    elements, messages = lit(vtkTable())
    assert any("the Scene is a vtkTable, which has no surfaces" in e
               for e in messages["ErrorEvent"]), messages
    assert elements.GetNumberOfCells() == 0


def with_reflectance(data, values, array=None):
    """`data` with the cell array Reflectance holding `values` (one grey value per cell)."""
    from vtkmodules.vtkCommonCore import vtkDoubleArray
    array = array or vtkDoubleArray()
    array.SetName(array.GetName() or "Reflectance")
    for value in values:
        array.InsertNextTuple(value if isinstance(value, tuple) else (value,))
    data.GetCellData().AddArray(array)
    return data


def test_messages_name_the_cell_as_the_input_numbers_it():
    # The surface of a grid or a multiblock numbers its faces otherwise: a message must give
    # the cell the spreadsheet shows, with its block.
    from vtkmodules.vtkCommonDataModel import (VTK_HEXAHEDRON, VTK_TETRA, vtkCompositeDataSet,
                                               vtkMultiBlockDataSet, vtkUnstructuredGrid)
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkFiltersSources import vtkCubeSource
    grid = vtkUnstructuredGrid()
    points = vtkPoints()
    for z in (0, 1):
        for y in (0, 1):
            for x in (0, 1):
                points.InsertNextPoint(x, y, z)
    for p in ((3, 0, 0), (4, 0, 0), (3, 1, 0), (3, 0, 1)):
        points.InsertNextPoint(*p)
    grid.SetPoints(points)
    grid.InsertNextCell(VTK_TETRA, 4, [8, 9, 10, 11])
    grid.InsertNextCell(VTK_HEXAHEDRON, 8, [0, 1, 3, 2, 4, 5, 7, 6])
    with_reflectance(grid, [0.5, 1.5])
    _, messages = lit(grid)
    assert any("Scene cell 1 has Reflectance (1.5, 1.5, 1.5)" in e
               for e in messages["ErrorEvent"]), messages

    def cube(bad_cell):
        source = vtkCubeSource()
        source.Update()
        return with_reflectance(source.GetOutput(), [2.0 if c == bad_cell else 0.5
                                                     for c in range(6)])

    blocks = vtkMultiBlockDataSet()
    blocks.SetBlock(0, grey_plane((-2, -2, 0), (2, -2, 0), (-2, 2, 0), 0.5))
    blocks.SetBlock(1, cube(3))
    _, messages = lit(blocks)
    assert any("Scene block 1 cell 3 has Reflectance (2, 2, 2)" in e
               for e in messages["ErrorEvent"]), messages

    # Nested, after an empty block, and named: block 2 of block 1, as the Multiblock Inspector
    # shows it.
    inner = vtkMultiBlockDataSet()
    inner.SetBlock(0, cube(-1))
    inner.SetBlock(2, cube(5))
    inner.GetMetaData(2).Set(vtkCompositeDataSet.NAME(), "box")
    blocks.SetBlock(1, inner)
    _, messages = lit(blocks)
    assert any("Scene block 1/2 'box' cell 5 has Reflectance (2, 2, 2)" in e
               for e in messages["ErrorEvent"]), messages


def test_points_no_polygon_uses_are_ignored_and_a_used_nan_is_named():
    import math
    from vtkmodules.vtkCommonCore import vtkPoints
    scene = grey_plane((0, 0, 0), (1, 0, 0), (0, 1, 0), 0.5)
    points = vtkPoints()
    points.DeepCopy(scene.GetPoints())
    points.InsertNextPoint(math.nan, 0, 0)  # point 4: no cell uses it
    scene.SetPoints(points)
    elements, messages = lit(scene)
    assert not messages["ErrorEvent"], messages
    assert surface_area(elements) == pytest.approx(1.0, rel=1e-9)

    points.SetPoint(2, 0, math.inf, 0)
    scene.Modified()
    _, messages = lit(scene)
    assert any("the Scene has 1 point with NaN or infinite coordinates in its polygons; the "
               "first is point 2 (0, inf, 0) of cell 0" in e
               for e in messages["ErrorEvent"]), messages


def test_a_reflectance_array_of_the_wrong_kind_says_what_to_do():
    from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkUnsignedCharArray
    scene = grey_plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
    values = vtkDoubleArray()
    values.SetName("Reflectance")
    for _ in range(scene.GetNumberOfPoints()):
        values.InsertNextValue(0.3)
    scene.GetPointData().AddArray(values)
    _, messages = lit(scene)
    assert any("no cell array Reflectance: every surface is grey 0.5: it has a point array "
               "Reflectance, but values are per cell: convert it with Point Data to Cell Data"
               in w for w in messages["WarningEvent"]), messages

    scene = grey_plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
    lower = vtkDoubleArray()
    lower.SetName("reflectance")
    with_reflectance(scene, [0.3], lower)
    _, messages = lit(scene)
    assert any("it has a cell array 'reflectance' (names differ in case): rename it "
               "Reflectance, or set ReflectanceArrayName to 'reflectance'" in w
               for w in messages["WarningEvent"]), messages

    scene = grey_plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
    colours = vtkUnsignedCharArray()
    colours.SetNumberOfComponents(3)
    with_reflectance(scene, [(200, 100, 50)], colours)
    _, messages = lit(scene)
    assert any("Scene cell 0 has Reflectance (200, 100, 50): every value must be >= 0 and < 1; "
               "it is an unsigned char array, colours from 0 to 255: divide it by 255" in e
               for e in messages["ErrorEvent"]), messages


def material_block(quads, names):
    """Quads [(origin, point1, point2, material id)] with MaterialId and MaterialNames, as the
    scene reader gives a file's materials."""
    from vtkmodules.vtkCommonCore import vtkIntArray, vtkStringArray
    from vtkmodules.vtkFiltersCore import vtkAppendPolyData
    append = vtkAppendPolyData()
    for origin, point1, point2, _ in quads:
        append.AddInputData(grey_plane(origin, point1, point2, 0.5))
    append.Update()
    data = append.GetOutput()
    ids = vtkIntArray()
    ids.SetName("MaterialId")
    for *_, material in quads:
        ids.InsertNextValue(material)
    data.GetCellData().AddArray(ids)
    table = vtkStringArray()
    table.SetName("MaterialNames")
    for name in names:
        table.InsertNextValue(name)
    data.GetFieldData().AddArray(table)
    return data


def test_a_multiblock_matches_materials_by_name():
    # Two files' materials in one multiblock: each block numbers its own from 0, so a Light
    # Material is found by name in any block, and only there.
    from vtkmodules.vtkCommonDataModel import vtkMultiBlockDataSet
    first = material_block([((0, 0, 0), (2, 0, 0), (0, 2, 0), 0),
                            ((0.8, 1.2, 1.5), (1.2, 1.2, 1.5), (0.8, 0.8, 1.5), 1)],
                           ["floor", "lamp"])
    second = material_block([((0, 0, 0), (0, 2, 0), (0, 0, 2), 0),
                             ((2, 0, 0), (2, 0, 2), (2, 2, 0), 1)],
                            ["wall", "other"])
    blocks = vtkMultiBlockDataSet()
    blocks.SetBlock(0, first)
    blocks.SetBlock(1, second)
    for material, polygons in (("lamp", 1), ("other", 1)):
        radiosity = vtkMovingLightRadiosity()
        radiosity.SetSceneData(blocks)
        radiosity.SetLightMaterial(material)
        radiosity.SetLightPowerFromMaterial(False)
        radiosity.SetNumberOfPositions(1)
        radiosity.SetNumberOfPaths(2000)
        radiosity.SetPatchSize(0.5)
        radiosity.SetNumberOfThreads(2)
        radiosity.SetErrorBatches(1)
        assert radiosity.UpdateTimeStep(0.0), material
        assert radiosity.GetOutput(2).GetNumberOfCells() == polygons, material


def test_the_scenes_own_cell_arrays_reach_every_element_and_patch():
    # Remeshing merges coplanar cells, so an element takes the values of the input cell under
    # its centroid: a zone, a label, a material and its name. A Radiosity the scene carries (an
    # earlier output read back) is not passed: the frame's own is the solver's.
    from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkIntArray, vtkStringArray
    from vtkmodules.vtkCommonDataModel import vtkMultiBlockDataSet
    from vtkmodules.vtkFiltersCore import vtkAppendPolyData

    def zoned(quads, materials):
        data = material_block([(o, p1, p2, m) for (o, p1, p2, _), m in zip(quads, materials)],
                              ["plaster", "oak"])
        zone, label, stale = vtkIntArray(), vtkStringArray(), vtkDoubleArray()
        zone.SetName("Zone")
        label.SetName("Label")
        stale.SetName("Radiosity")
        stale.SetNumberOfComponents(3)
        for *_, z in quads:
            zone.InsertNextValue(z)
            label.InsertNextValue(f"zone {z}")
            stale.InsertNextTuple3(1e6, 1e6, 1e6)
        for array in (zone, label, stale):
            data.GetCellData().AddArray(array)
        return data

    blocks = vtkMultiBlockDataSet()
    # One floor in two coplanar halves, which remeshing merges, and a wall.
    blocks.SetBlock(0, zoned([((0, 0, 0), (0.5, 0, 0), (0, 1, 0), 1),
                              ((0.5, 0, 0), (1, 0, 0), (0.5, 1, 0), 2)], [0, 1]))
    blocks.SetBlock(1, zoned([((0, 0, 0), (0, 0, 1), (0, 1, 0), 3)], [0]))
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(blocks)
    radiosity.SetLightTypeToDirectional()
    radiosity.SetPathStart(0, 0, 1)
    radiosity.SetPathEnd(0, 0, 1)
    radiosity.SetNumberOfPositions(1)
    radiosity.SetNumberOfPaths(4000)
    radiosity.SetPatchSize(0.2)
    radiosity.SetNumberOfThreads(2)
    radiosity.SetErrorBatches(1)
    messages = {event: recorded(radiosity, event) for event in ("ErrorEvent", "WarningEvent")}
    radiosity.Update()
    assert not messages["ErrorEvent"], messages
    for port in (0, 1):
        mesh = radiosity.GetOutput(port)
        zone = mesh.GetCellData().GetArray("Zone")
        label = mesh.GetCellData().GetAbstractArray("Label")
        material = mesh.GetCellData().GetArray("MaterialId")
        names = mesh.GetFieldData().GetAbstractArray("MaterialNames")
        assert zone and label and material and names, port
        seen = set()
        for c in range(mesh.GetNumberOfCells()):
            cell = mesh.GetCell(c).GetPoints()
            x, _, z = numpy.mean([cell.GetPoint(i) for i in range(3)], axis=0)
            if abs(x - 0.5) < 1e-6:
                continue  # on the line between the halves: either is right
            expected = 3 if z > 1e-6 else (1 if x < 0.5 else 2)
            assert zone.GetValue(c) == expected, (port, c, x, z)
            assert label.GetValue(c) == f"zone {expected}", (port, c)
            assert names.GetValue(int(material.GetValue(c))) == \
                ("oak" if expected == 2 else "plaster"), (port, c)
            seen.add(expected)
        assert seen == {1, 2, 3}, port
    radiosity_array = vtk_to_numpy(radiosity.GetOutput(0).GetCellData().GetArray("Radiosity"))
    assert radiosity_array.max() < 1e5  # the solver's, not the stale 1e6
    assert sum("the Scene's cell array 'Radiosity' has the name of an output array" in w
               for w in messages["WarningEvent"]) == 1, messages  # one warning, not per block

    # An array of another length than the cells would be read past its end: left out, named.
    plane = grey_plane((0, 0, 0), (1, 0, 0), (0, 1, 0), 0.5)
    short = vtkIntArray()
    short.SetName("Zone")
    plane.GetCellData().AddArray(short)
    elements, messages = lit(plane)
    assert not messages["ErrorEvent"], messages
    assert any("the Scene's cell array 'Zone' has 0 values for 1 cell: it is not passed" in w
               for w in messages["WarningEvent"]), messages
    assert elements.GetCellData().GetArray("Zone") is None


def test_a_light_material_that_emits_nothing_says_what_it_emits_instead():
    # A material with no emission cannot give the light's power: LightPower does, said once.
    blocks = material_block([((0, 0, 0), (2, 0, 0), (0, 2, 0), 0),
                             ((0.8, 1.2, 1.5), (1.2, 1.2, 1.5), (0.8, 0.8, 1.5), 1)],
                            ["floor", "lamp"])
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(blocks)
    radiosity.SetLightMaterial("lamp")
    radiosity.SetLightPower(30, 20, 10)
    radiosity.SetNumberOfPositions(1)
    radiosity.SetNumberOfPaths(2000)
    radiosity.SetPatchSize(0.5)
    radiosity.SetErrorBatches(1)
    messages = {event: recorded(radiosity, event) for event in ("ErrorEvent", "WarningEvent")}
    assert radiosity.UpdateTimeStep(0.0)
    assert not messages["ErrorEvent"], messages
    assert sum("the LightMaterial 'lamp' emits nothing of its own (no emission): the light "
               "emits LightPower, 30, 20, 10 W" in w for w in messages["WarningEvent"]) == 1, \
        messages
    assert field(radiosity.GetOutput(3), "LightPower") == pytest.approx((30, 20, 10))


def lamp_scene():
    """A floor and, 1.5 above it, a lamp material of two quads facing down: area centroid
    (0.4333, 1.4167, 1.5), not the mean of its points (x 0.55)."""
    scene = material_block([((0, 0, 0), (2, 0, 0), (0, 2, 0), 0),
                            ((0.2, 1.6, 1.5), (0.6, 1.6, 1.5), (0.2, 1.2, 1.5), 1),
                            ((0.6, 1.6, 1.5), (0.8, 1.6, 1.5), (0.6, 1.5, 1.5), 1)],
                           ["floor", "lamp"])
    centroid = ((0.16 * 0.4 + 0.02 * 0.7) / 0.18, (0.16 * 1.4 + 0.02 * 1.55) / 0.18, 1.5)
    return scene, centroid


def light_material_filter(scene):
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(scene)
    radiosity.SetLightMaterial("lamp")
    radiosity.SetNumberOfPositions(3)
    radiosity.SetNumberOfPaths(2000)
    radiosity.SetPatchSize(0.5)
    radiosity.SetNumberOfThreads(2)
    radiosity.SetErrorBatches(1)
    return radiosity


def sorted_points(data):
    return sorted(tuple(round(c, 9) for c in data.GetPoint(i)) for i in range(data.GetNumberOfPoints()))


def test_a_light_material_starts_where_the_scene_has_it():
    # ParaView gives the straight path the middles of the Scene's -x and +x faces: the lamp
    # jumped there in the first frame. It starts where the scene has it and moves to PathEnd.
    scene, centroid = lamp_scene()
    lamp_points = sorted_points(light_material_filter_lamp(scene))
    for bounds_path in (True, False):  # ParaView's defaults, then the filter's own
        radiosity = light_material_filter(scene)
        # Off by default in VTK, so that a script's PathStart keeps its meaning; on in ParaView.
        assert not radiosity.GetPathFromLightMaterial()
        radiosity.PathFromLightMaterialOn()
        if bounds_path:
            radiosity.SetPathStart(0, 1, 0.75)
            radiosity.SetPathEnd(2, 1, 0.75)
        end = radiosity.GetPathEnd()
        errors = recorded(radiosity, "ErrorEvent")
        assert radiosity.UpdateTimeStep(0.0), errors
        assert field(radiosity.GetOutput(0), "LightPosition") == pytest.approx(centroid, abs=1e-6)
        assert field(radiosity.GetOutput(0), "LightTranslation") == pytest.approx((0, 0, 0),
                                                                                  abs=1e-12)
        # The Light output is the lamp's polygons as the scene has them, not moved.
        assert radiosity.GetOutput(2).GetNumberOfCells() == 2
        assert sorted_points(radiosity.GetOutput(2)) == pytest.approx(lamp_points, abs=1e-12)
        assert radiosity.UpdateTimeStep(1.0)
        middle = [(c + e) / 2 for c, e in zip(centroid, end)]
        assert field(radiosity.GetOutput(0), "LightPosition") == pytest.approx(middle, abs=1e-6)
        assert radiosity.UpdateTimeStep(2.0)
        assert field(radiosity.GetOutput(0), "LightPosition") == pytest.approx(end, abs=1e-12)

    # Off: from PathStart, as for a Light input.
    radiosity = light_material_filter(scene)
    radiosity.SetPathStart(0, 1, 0.75)
    radiosity.SetPathEnd(2, 1, 0.75)
    assert radiosity.UpdateTimeStep(0.0)
    assert field(radiosity.GetOutput(0), "LightPosition") == pytest.approx((0, 1, 0.75))


def light_material_filter_lamp(scene):
    """The lamp's polygons as the scene holds them: its cells of MaterialId 1."""
    from vtkmodules.vtkFiltersCore import vtkThreshold
    from vtkmodules.vtkFiltersGeometry import vtkGeometryFilter
    threshold = vtkThreshold()
    threshold.SetInputData(scene)
    threshold.SetInputArrayToProcess(0, 0, 0, 1, "MaterialId")  # cells
    threshold.SetLowerThreshold(1)
    threshold.SetUpperThreshold(1)
    surface = vtkGeometryFilter()
    surface.SetInputConnection(threshold.GetOutputPort())
    surface.Update()
    return surface.GetOutput()


def test_an_empty_light_is_named_before_nothing_emits():
    from vtkmodules.vtkCommonDataModel import vtkPolyData
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(grey_plane((0, 0, 0), (1, 0, 0), (0, 1, 0), 0.5))
    radiosity.SetLightData(vtkPolyData())
    radiosity.SetNumberOfThreads(2)
    messages = recorded(radiosity, "WarningEvent", "ErrorEvent")
    assert not radiosity.UpdateTimeStep(0.0)
    assert any("the Light input is connected but empty" in m for m in messages), messages
    assert any("nothing emits light" in m for m in messages), messages


def test_an_empty_scene_is_named():
    """A Scene that an upstream filter emptied (a Threshold keeping nothing) gave empty outputs
    and not a word (QA)."""
    from vtkmodules.vtkCommonDataModel import vtkPolyData
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(vtkPolyData())
    radiosity.SetNumberOfThreads(2)
    messages = recorded(radiosity, "WarningEvent", "ErrorEvent")
    radiosity.UpdateTimeStep(0.0)
    assert radiosity.GetOutput(0).GetNumberOfCells() == 0
    assert any("the Scene input is connected but empty" in m for m in messages), messages


def test_a_trajectory_that_is_a_time_series_is_named():
    """A .pvd of one point per time step is no path: its first step alone became a single
    frame, without a word (QA). It is now named, with what to give."""
    from vtkmodules.util.vtkAlgorithm import VTKPythonAlgorithmBase
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkPolyData

    class OnePointPerStep(VTKPythonAlgorithmBase):
        def __init__(self):
            super().__init__(nInputPorts=0, nOutputPorts=1, outputType="vtkPolyData")

        def RequestInformation(self, request, inInfo, outInfo):
            info = outInfo.GetInformationObject(0)
            info.Set(vtkStreamingDemandDrivenPipeline.TIME_STEPS(), [0.0, 1.0, 2.0], 3)
            info.Set(vtkStreamingDemandDrivenPipeline.TIME_RANGE(), [0.0, 2.0], 2)
            return 1

        def RequestData(self, request, inInfo, outInfo):
            points = vtkPoints()
            points.InsertNextPoint(0.25, 0.5478, 0.25)
            vtkPolyData.GetData(outInfo).SetPoints(points)
            return 1

    series = OnePointPerStep()
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(grey_plane((0, 0, 0), (1, 0, 0), (0, 1, 0), 0.5))
    radiosity.SetLightTypeToPoint()
    radiosity.SetInputConnection(2, series.GetOutputPort())
    radiosity.SetNumberOfPaths(2000)
    radiosity.SetNumberOfThreads(2)
    messages = recorded(radiosity, "WarningEvent")
    assert radiosity.UpdateTimeStep(0.0)
    assert any("the Trajectory input has 3 time steps: only its first (time 0) is used; give "
               "one data set whose points are the light's positions" in m for m in messages), \
        messages


def test_inputs_and_properties_that_change_nothing_are_warned_of():
    """A Light input beside LightType Point or Directional, a Trajectory with only the Scene's
    own emitters, a TimeLimit without a target: accepted silently, where the command line
    refuses the like (QA)."""
    from vtkmodules.vtkCommonCore import vtkDoubleArray
    floor = grey_plane((-1, -1, 0), (1, -1, 0), (-1, 1, 0), 0.5)
    lamp = grey_plane((-0.1, -0.1, 1), (-0.1, 0.1, 1), (0.1, -0.1, 1))
    line = vtkLineSource()
    line.SetPoint1(-0.5, 0, 1)
    line.SetPoint2(0.5, 0, 1)
    line.SetResolution(2)
    line.Update()

    def warnings(configure):
        radiosity = vtkMovingLightRadiosity()
        radiosity.SetSceneData(floor)
        radiosity.SetNumberOfPaths(2000)
        radiosity.SetNumberOfThreads(2)
        configure(radiosity)
        messages = recorded(radiosity, "WarningEvent", "ErrorEvent")
        assert radiosity.UpdateTimeStep(0.0), messages
        return messages

    def point(r):
        r.SetLightTypeToPoint()
        r.SetLightData(lamp)
        r.SetTrajectoryData(line.GetOutput())
    assert any("the Light input is not used: LightType Point" in m for m in warnings(point))

    def sun(r):
        r.SetLightTypeToDirectional()
        r.SetLightData(lamp)
        r.SetPathStart(0, 0, 1)
        r.SetPathEnd(1, 0, 1)
    assert any("the Light input is not used: LightType Directional" in m for m in warnings(sun))

    # Both blocks carry both arrays, which vtkAppendPolyData keeps only when all have them.
    glowing = grey_plane((-0.1, -0.1, 1), (-0.1, 0.1, 1), (0.1, -0.1, 1), 0.5)
    dark = grey_plane((-1, -1, 0), (1, -1, 0), (-1, 1, 0), 0.5)
    for data, value in ((glowing, 100), (dark, 0)):
        emission = vtkDoubleArray()
        emission.SetName("Emission")
        emission.SetNumberOfComponents(3)
        emission.InsertNextTuple3(value, value, value)
        data.GetCellData().AddArray(emission)
    from vtkmodules.vtkFiltersCore import vtkAppendPolyData
    both = vtkAppendPolyData()
    both.AddInputData(dark)
    both.AddInputData(glowing)
    both.Update()

    def emitters(r):
        r.SetSceneData(both.GetOutput())
        r.SetTrajectoryData(line.GetOutput())
    assert any("the Trajectory moves no light" in m for m in warnings(emitters))

    def limit(r):
        r.SetLightData(lamp)
        r.SetTimeLimit(60)
    assert any("TimeLimit stops the rounds of a TargetRelativeError" in m
               for m in warnings(limit))
    # An area light, its Trajectory and a target with its limit: nothing to say.
    def plain(r):
        r.SetLightData(lamp)
        r.SetTrajectoryData(line.GetOutput())
        r.SetTargetRelativeError(0.5)
        r.SetTimeLimit(60)
    assert not any("not used" in m or "moves no light" in m or "TimeLimit" in m
                   for m in warnings(plain))


def test_a_light_material_that_takes_the_whole_scene_is_an_error():
    radiosity = vtkMovingLightRadiosity()
    radiosity.SetSceneData(material_block([((0, 0, 0), (1, 0, 0), (0, 1, 0), 0)], ["lamp"]))
    radiosity.SetLightMaterial("lamp")
    radiosity.SetLightPowerFromMaterial(False)
    radiosity.SetNumberOfThreads(2)
    errors = recorded(radiosity, "ErrorEvent")
    assert not radiosity.UpdateTimeStep(0.0)
    assert any("LightMaterial 'lamp' takes every polygon of the Scene" in e for e in errors), errors


def test_material_ids_that_are_not_whole_numbers_are_named():
    # A float MaterialId of 0.5 is no material: refused, not rounded to one, alone or in a
    # multiblock (whose blocks' materials are renumbered by name).
    from vtkmodules.vtkCommonCore import vtkFloatArray
    from vtkmodules.vtkCommonDataModel import vtkMultiBlockDataSet
    scene = material_block([((0, 0, 0), (2, 0, 0), (0, 2, 0), 0),
                            ((0.8, 1.2, 1.5), (1.2, 1.2, 1.5), (0.8, 0.8, 1.5), 1)],
                           ["floor", "lamp"])
    ids = vtkFloatArray()
    ids.SetName("MaterialId")
    for value in (0, 0.5):
        ids.InsertNextValue(value)
    scene.GetCellData().AddArray(ids)
    blocks = vtkMultiBlockDataSet()
    blocks.SetBlock(0, scene)
    for data, place in ((scene, "cell 1"), (blocks, "block 0 cell 1")):
        radiosity = vtkMovingLightRadiosity()
        radiosity.SetSceneData(data)
        radiosity.SetLightMaterial("lamp")
        radiosity.SetNumberOfThreads(2)
        errors = recorded(radiosity, "ErrorEvent")
        assert not radiosity.UpdateTimeStep(0.0)
        assert any(f"MaterialId holds 0.5 ({place}): give whole numbers" in e
                   for e in errors), errors


def test_a_light_of_any_data_set_lights_as_its_polygons():
    # A Plane made an unstructured grid (as Clip or Threshold give it) is the same light.
    from vtkmodules.vtkFiltersCore import vtkAppendFilter as Append
    results = []
    for make_grid in (False, True):
        lamp = grey_plane((0.4, 0.6, 1), (0.6, 0.6, 1), (0.4, 0.4, 1))  # facing down
        if make_grid:
            grid = Append()
            grid.AddInputData(lamp)
            grid.Update()
            lamp = grid.GetOutput()
        radiosity = vtkMovingLightRadiosity()
        radiosity.SetSceneData(grey_plane((0, 0, 0), (1, 0, 0), (0, 1, 0), 0.5))
        radiosity.SetLightData(lamp)
        radiosity.SetNumberOfPositions(1)
        radiosity.SetNumberOfPaths(2000)
        radiosity.SetNumberOfThreads(2)
        radiosity.SetErrorBatches(1)
        errors = recorded(radiosity, "ErrorEvent")
        assert radiosity.UpdateTimeStep(0.0), errors
        assert radiosity.GetOutput(2).GetNumberOfCells() == 1
        radiance = radiosity.GetOutput(0).GetCellData().GetArray("Radiosity")
        results.append([radiance.GetTuple(c) for c in range(radiance.GetNumberOfTuples())])
    assert results[0] == results[1]
