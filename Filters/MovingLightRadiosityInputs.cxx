#include "MovingLightRadiosityInputs.h"

#include "Error.h"
#include "MemoryBudget.h"
#include "Plural.h"
#include "PolygonTriangulation.h"

#include "vtkAppendPolyData.h"
#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkCellData.h"
#include "vtkCompositeDataIterator.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataArray.h"
#include "vtkDataObjectTreeIterator.h"
#include "vtkDataSet.h"
#include "vtkFieldData.h"
#include "vtkGeometryFilter.h"
#include "vtkInformation.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStringArray.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <sstream>

namespace mlr::vtkinputs
{

namespace
{
// What surfaceOf adds to the surface of an input that is not a vtkPolyData, so that messages
// name the cells and points the user sees in the spreadsheet: the input's own ids, and the
// block of a composite input.
const char* const InputCellIds = "MovingLightRadiosityInputCellId";
const char* const InputPointIds = "MovingLightRadiosityInputPointId";
const char* const InputBlock = "MovingLightRadiosityInputBlock";
const char* const InputBlockNames = "MovingLightRadiosityInputBlockNames";

/// Element `id` of the id array `name` of `data`, or `id` itself without it.
vtkIdType inputIdOf(vtkDataSetAttributes* data, const char* name, vtkIdType id)
{
  auto* ids = vtkDataArray::SafeDownCast(data->GetAbstractArray(name));
  return ids && id < ids->GetNumberOfTuples() ? static_cast<vtkIdType>(ids->GetComponent(id, 0))
                                              : id;
}

/// "block 1 " for the surface's cell `cellId` from a composite input's block 1, else "".
std::string blockOf(vtkPolyData* surface, vtkIdType cellId)
{
  auto* names =
    vtkStringArray::SafeDownCast(surface->GetFieldData()->GetAbstractArray(InputBlockNames));
  auto* blocks = vtkDataArray::SafeDownCast(surface->GetCellData()->GetAbstractArray(InputBlock));
  if (!names || !blocks || cellId >= blocks->GetNumberOfTuples())
  {
    return "";
  }
  const auto block = static_cast<vtkIdType>(blocks->GetComponent(cellId, 0));
  return block >= 0 && block < names->GetNumberOfValues() ? names->GetValue(block) + " " : "";
}

/// The surface's cell `cellId` as the input has it: "cell 7" of a vtkPolyData (its own id),
/// else the input cell it is a face of, in its block ("block 1 cell 3").
std::string cellPlace(vtkPolyData* surface, vtkIdType cellId)
{
  return blockOf(surface, cellId) + "cell " +
    std::to_string(inputIdOf(surface->GetCellData(), InputCellIds, cellId));
}

/// The surface's point `pointId` as the input (its block, for a composite) numbers it.
std::string pointPlace(vtkPolyData* surface, vtkIdType pointId)
{
  return "point " + std::to_string(inputIdOf(surface->GetPointData(), InputPointIds, pointId));
}

/// Calls visit(cellId, pointIds) for every polygon of `data`, then for every triangle of its
/// strips, with the cell ids vtkPolyData gives them (vertices, lines, polygons, strips).
void forEachSurfaceCell(
  vtkPolyData* data, const std::function<void(vtkIdType, const std::vector<std::uint32_t>&)>& visit)
{
  vtkIdType cellId = data->GetNumberOfVerts() + data->GetNumberOfLines();
  std::vector<std::uint32_t> ids;
  vtkIdType count = 0;
  const vtkIdType* points = nullptr;

  auto polys = vtkSmartPointer<vtkCellArrayIterator>::Take(data->GetPolys()->NewIterator());
  for (polys->GoToFirstCell(); !polys->IsDoneWithTraversal(); polys->GoToNextCell(), ++cellId)
  {
    polys->GetCurrentCell(count, points);
    ids.assign(points, points + count);
    visit(cellId, ids);
  }

  auto strips = vtkSmartPointer<vtkCellArrayIterator>::Take(data->GetStrips()->NewIterator());
  for (strips->GoToFirstCell(); !strips->IsDoneWithTraversal(); strips->GoToNextCell(), ++cellId)
  {
    strips->GetCurrentCell(count, points);
    for (vtkIdType j = 0; j + 2 < count; ++j)
    {
      // Every other triangle of a strip runs backwards: swap its first two points so that
      // all of them face the strip's way.
      const vtkIdType a = points[j + (j % 2)], b = points[j + 1 - (j % 2)], c = points[j + 2];
      if (a == b || b == c || a == c)
      {
        continue; // the degenerate triangles that stitch strips together
      }
      ids.assign({ static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b),
        static_cast<std::uint32_t>(c) });
      visit(cellId, ids);
    }
  }
}

std::vector<Vec3> pointsOf(vtkPointSet* data)
{
  std::vector<Vec3> result;
  vtkPoints* points = data->GetPoints();
  const vtkIdType n = points ? points->GetNumberOfPoints() : 0;
  result.resize(static_cast<std::size_t>(n));
  double p[3];
  for (vtkIdType i = 0; i < n; ++i)
  {
    points->GetPoint(i, p);
    result[static_cast<std::size_t>(i)] = { p[0], p[1], p[2] };
  }
  return result;
}

/// The Scene's cell array `name` (numeric, 1 or 3 components), or nullptr when absent.
vtkDataArray* colourArray(vtkPolyData* scene, const std::string& name, const char* values)
{
  vtkAbstractArray* array =
    name.empty() ? nullptr : scene->GetCellData()->GetAbstractArray(name.c_str());
  if (!array)
  {
    return nullptr;
  }
  auto* numbers = vtkDataArray::SafeDownCast(array);
  if (!numbers)
  {
    throw Error("the Scene's cell array " + name + " is a " + array->GetClassName() +
      ": give a numeric array (float or double) with values " + values);
  }
  const int components = numbers->GetNumberOfComponents();
  if (components != 1 && components != 3)
  {
    throw Error("the Scene's cell array " + name + " has " + std::to_string(components) +
      " components: give 3 (red, green, blue) or 1 (grey)");
  }
  if (numbers->GetNumberOfTuples() < scene->GetNumberOfCells())
  {
    throw Error("the Scene's cell array " + name + " has " +
      std::to_string(numbers->GetNumberOfTuples()) + " values for " +
      std::to_string(scene->GetNumberOfCells()) + " cells: give one per cell");
  }
  return numbers;
}

/// What the Scene has instead of its cell array `name`: a point array of that name, or an
/// array whose name differs only in case; "" when nothing like it.
std::string lookalikeOf(vtkPolyData* scene, const std::string& name, const std::string& property)
{
  if (name.empty())
  {
    return "";
  }
  if (scene->GetPointData()->GetAbstractArray(name.c_str()))
  {
    return ": it has a point array " + name +
      ", but values are per cell: convert it with Point Data to Cell Data "
      "(vtkPointDataToCellData)";
  }
  auto lower = [](std::string text)
  {
    std::transform(text.begin(), text.end(), text.begin(),
      [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return text;
  };
  for (vtkDataSetAttributes* data : { static_cast<vtkDataSetAttributes*>(scene->GetCellData()),
         static_cast<vtkDataSetAttributes*>(scene->GetPointData()) })
  {
    for (int a = 0; a < data->GetNumberOfArrays(); ++a)
    {
      const char* other = data->GetArrayName(a);
      if (other && lower(other) == lower(name))
      {
        return std::string(": it has a ") + (data == scene->GetCellData() ? "cell" : "point") +
          " array '" + other + "' (names differ in case): rename it " + name + ", or set " +
          property + " to '" + other + "' (in ParaView or Python)" +
          (data == scene->GetCellData()
              ? ""
              : ", and convert it with Point Data to Cell Data (vtkPointDataToCellData)");
      }
    }
  }
  return "";
}

Rgb colourOfCell(vtkDataArray* array, vtkIdType cellId)
{
  if (array->GetNumberOfComponents() == 1)
  {
    return Rgb(array->GetComponent(cellId, 0));
  }
  return Rgb(
    array->GetComponent(cellId, 0), array->GetComponent(cellId, 1), array->GetComponent(cellId, 2));
}

Rgb reflectanceOfCell(
  vtkPolyData* scene, vtkDataArray* array, vtkIdType cellId, const std::string& name)
{
  const Rgb rho = colourOfCell(array, cellId);
  for (int c = 0; c < 3; ++c)
  {
    if (!(rho[c] >= 0.0 && rho[c] < 1.0))
    {
      std::ostringstream s;
      s << "Scene " << cellPlace(scene, cellId) << " has " << name << " (" << rho.r << ", " << rho.g
        << ", " << rho.b << "): every value must be >= 0 and < 1";
      if (array->GetDataType() == VTK_UNSIGNED_CHAR && rho.maxComponent() >= 1)
      {
        // Colours read from images and PLY files come as bytes.
        s << "; it is an unsigned char array, colours from 0 to 255: divide it by 255 (a "
          << "Calculator on Cell Data: " << name << "/255) to give fractions";
      }
      throw Error(s.str());
    }
  }
  return rho;
}

Rgb emissionOfCell(
  vtkPolyData* scene, vtkDataArray* array, vtkIdType cellId, const std::string& name)
{
  const Rgb e = colourOfCell(array, cellId);
  if (!e.isFinite() || e.minComponent() < 0)
  {
    std::ostringstream s;
    s << "Scene " << cellPlace(scene, cellId) << " has " << name << " (" << e.r << ", " << e.g
      << ", " << e.b << ") W/m^2: every value must be finite and >= 0";
    throw Error(s.str());
  }
  return e;
}

/// The numeric point array `name` with `components` (or, when `alternative` is not 0,
/// that many) components and one tuple per point, or nullptr when absent.
vtkDataArray* pointArray(vtkPointSet* data, const char* name, int components, int alternative = 0)
{
  vtkAbstractArray* array = data->GetPointData()->GetAbstractArray(name);
  if (!array)
  {
    return nullptr;
  }
  auto* numbers = vtkDataArray::SafeDownCast(array);
  const int c = numbers ? numbers->GetNumberOfComponents() : 0;
  if (!numbers || (c != components && (alternative == 0 || c != alternative)) ||
    numbers->GetNumberOfTuples() != data->GetNumberOfPoints())
  {
    std::string shape = std::to_string(components);
    if (alternative)
    {
      shape += " or " + std::to_string(alternative);
    }
    throw Error(std::string("the Trajectory's point array ") + name + " must be numeric with " +
      shape + " components and one tuple per point (" + std::to_string(data->GetNumberOfPoints()) +
      "): fix it or remove it");
  }
  return numbers;
}

/// Refuses a MaterialId array `ids` of `surface` of floating-point values that are not whole
/// numbers, rather than rounding them to some material; the message names the cell as the
/// input has it, in its `block` ("block 1") of a composite input not yet joined.
void checkWholeMaterialIds(vtkPolyData* surface, vtkDataArray* ids, const std::string& block)
{
  if (ids->GetDataType() != VTK_FLOAT && ids->GetDataType() != VTK_DOUBLE)
  {
    return;
  }
  for (vtkIdType cell = 0; cell < ids->GetNumberOfTuples(); ++cell)
  {
    const double id = ids->GetComponent(cell, 0);
    if (id != std::floor(id))
    {
      std::ostringstream s;
      s << "the Scene's cell array MaterialId holds " << id << " ("
        << (block.empty() ? cellPlace(surface, cell)
                          : block + " cell " +
                 std::to_string(inputIdOf(surface->GetCellData(), InputCellIds, cell)))
        << "): give whole numbers, each an index into the field data MaterialNames";
      throw Error(s.str());
    }
  }
}

/// The Scene's cell array MaterialId (one integer per cell), or nullptr.
vtkDataArray* materialIdArray(vtkPolyData* scene)
{
  auto* ids = vtkDataArray::SafeDownCast(scene->GetCellData()->GetAbstractArray("MaterialId"));
  if (!ids || ids->GetNumberOfComponents() != 1 ||
    ids->GetNumberOfTuples() < scene->GetNumberOfCells())
  {
    return nullptr;
  }
  checkWholeMaterialIds(scene, ids, "");
  return ids;
}

/// The integer cell array LightId of the Light, or nullptr.
vtkDataArray* lightIdArray(vtkPolyData* light)
{
  vtkAbstractArray* array = light ? light->GetCellData()->GetAbstractArray("LightId") : nullptr;
  if (!array)
  {
    return nullptr;
  }
  auto* ids = vtkDataArray::SafeDownCast(array);
  if (!ids || ids->GetNumberOfComponents() != 1 ||
    ids->GetNumberOfTuples() < light->GetNumberOfCells())
  {
    throw Error("the Light's cell array LightId must be numeric with one integer per cell: fix "
                "it or remove it to make every polygon one light");
  }
  return ids;
}

/// The sorted distinct LightId values, checked to be integers.
std::vector<long long> distinctLightIds(vtkPolyData* light, vtkDataArray* ids)
{
  std::vector<long long> values;
  for (vtkIdType c = 0; c < light->GetNumberOfCells(); ++c)
  {
    const double v = ids->GetComponent(c, 0);
    if (!std::isfinite(v) || v != std::floor(v))
    {
      std::ostringstream s;
      s << "the Light's cell array LightId has " << v << " at " << cellPlace(light, c)
        << ": give integers (0, 1, ...) that group polygons into lights";
      throw Error(s.str());
    }
    values.push_back(static_cast<long long>(v));
  }
  std::sort(values.begin(), values.end());
  values.erase(std::unique(values.begin(), values.end()), values.end());
  return values;
}

/// Every leaf of `data` with its label, null and empty ones included so that a leaf's number
/// is the same on every rank. The label is the block's index, as the Multiblock Inspector and
/// the spreadsheet's unnamed_block_N give it ("block 1"; block 2 of block 1 is "block 1/2"),
/// and its name when it has one.
std::vector<std::pair<vtkDataObject*, std::string>> leavesOf(
  vtkCompositeDataSet* data, const std::string& path = "")
{
  std::vector<std::pair<vtkDataObject*, std::string>> leaves;
  vtkSmartPointer<vtkCompositeDataIterator> child;
  child.TakeReference(data->NewIterator());
  auto* tree = vtkDataObjectTreeIterator::SafeDownCast(child);
  if (!tree)
  {
    // Not a tree (AMR): its leaves have no block index, but a flat one.
    for (child->InitTraversal(); !child->IsDoneWithTraversal(); child->GoToNextItem())
    {
      leaves.emplace_back(
        child->GetCurrentDataObject(), "block " + std::to_string(child->GetCurrentFlatIndex()));
    }
    return leaves;
  }
  tree->VisitOnlyLeavesOff();
  tree->TraverseSubTreeOff();
  tree->SkipEmptyNodesOff();
  int index = 0;
  for (tree->InitTraversal(); !tree->IsDoneWithTraversal(); tree->GoToNextItem(), ++index)
  {
    const std::string label = (path.empty() ? "block " : path + "/") + std::to_string(index);
    vtkDataObject* object = tree->GetCurrentDataObject();
    if (auto* inner = vtkCompositeDataSet::SafeDownCast(object))
    {
      for (auto& leaf : leavesOf(inner, label))
      {
        leaves.push_back(std::move(leaf));
      }
      continue;
    }
    const char* name = tree->HasCurrentMetaData()
      ? tree->GetCurrentMetaData()->Get(vtkCompositeDataSet::NAME())
      : nullptr;
    leaves.emplace_back(object, name && *name ? label + " '" + name + "'" : label);
  }
  return leaves;
}
}

vtkSmartPointer<vtkPolyData> surfaceOf(vtkDataObject* input, const std::string& port,
  std::vector<std::string>& warnings, const std::vector<std::pair<std::string, double>>& fills)
{
  if (!input)
  {
    return nullptr;
  }
  if (auto* polygons = vtkPolyData::SafeDownCast(input))
  {
    return polygons;
  }
  auto boundaryOf = [](vtkDataSet* data)
  {
    vtkNew<vtkGeometryFilter> surface;
    surface->SetInputData(data);
    surface->PassThroughCellIdsOn();
    surface->SetOriginalCellIdsName(InputCellIds);
    surface->PassThroughPointIdsOn();
    surface->SetOriginalPointIdsName(InputPointIds);
    surface->Update();
    return vtkSmartPointer<vtkPolyData>(surface->GetOutput());
  };
  if (auto* data = vtkDataSet::SafeDownCast(input))
  {
    return boundaryOf(data);
  }
  auto* composite = vtkCompositeDataSet::SafeDownCast(input);
  if (!composite)
  {
    throw Error("the " + port + " is a " + input->GetClassName() +
      ", which has no surfaces: give a data set (polygons, or cells whose boundary is the "
      "surface to light) or a multiblock of them");
  }
  vtkNew<vtkAppendPolyData> append;
  std::map<std::string, int> arrayLeaves;
  int leaves = 0;
  std::vector<std::pair<vtkSmartPointer<vtkPolyData>, std::string>> surfaces;
  // Materials (cell array MaterialId into field data MaterialNames, as the scene reader gives
  // them) are matched by name over the blocks: each block's ids are renumbered into one list.
  vtkNew<vtkStringArray> materialNames;
  materialNames->SetName("MaterialNames");
  std::map<std::string, int> materialIndex;
  vtkNew<vtkStringArray> blockNames;
  blockNames->SetName(InputBlockNames);
  for (const auto& [leaf, label] : leavesOf(composite))
  {
    const auto block = static_cast<int>(blockNames->InsertNextValue(label));
    auto* data = vtkDataSet::SafeDownCast(leaf);
    if (!data || data->GetNumberOfCells() == 0)
    {
      continue;
    }
    vtkSmartPointer<vtkPolyData> surface = boundaryOf(data);
    auto* names =
      vtkStringArray::SafeDownCast(surface->GetFieldData()->GetAbstractArray("MaterialNames"));
    auto* ids = vtkDataArray::SafeDownCast(surface->GetCellData()->GetAbstractArray("MaterialId"));
    if (names && ids)
    {
      checkWholeMaterialIds(surface, ids, label);
      // A copy, so that the block's own arrays stay as they are.
      auto renumbered = vtkSmartPointer<vtkPolyData>::New();
      renumbered->ShallowCopy(surface);
      vtkSmartPointer<vtkDataArray> merged;
      merged.TakeReference(ids->NewInstance());
      merged->SetName("MaterialId");
      merged->SetNumberOfTuples(ids->GetNumberOfTuples());
      for (vtkIdType c = 0; c < ids->GetNumberOfTuples(); ++c)
      {
        const auto id = static_cast<vtkIdType>(ids->GetComponent(c, 0));
        const std::string name = id >= 0 && id < names->GetNumberOfValues()
          ? names->GetValue(id)
          : "material " + std::to_string(id);
        auto found = materialIndex.find(name);
        if (found == materialIndex.end())
        {
          found = materialIndex.emplace(name, static_cast<int>(materialIndex.size())).first;
          materialNames->InsertNextValue(name);
        }
        merged->SetComponent(c, 0, found->second);
      }
      renumbered->GetCellData()->AddArray(merged);
      surface = renumbered;
    }
    vtkNew<vtkIntArray> blockOfCell;
    blockOfCell->SetName(InputBlock);
    blockOfCell->SetNumberOfTuples(surface->GetNumberOfCells());
    blockOfCell->FillValue(block);
    surface->GetCellData()->AddArray(blockOfCell);
    vtkCellData* cells = surface->GetCellData();
    for (int a = 0; a < cells->GetNumberOfArrays(); ++a)
    {
      if (const char* name = cells->GetArrayName(a))
      {
        ++arrayLeaves[name];
      }
    }
    surfaces.emplace_back(surface, label);
    ++leaves;
  }
  if (leaves == 0)
  {
    return vtkSmartPointer<vtkPolyData>::New();
  }
  // A material array that some blocks lack takes its default on them: dropping it would take
  // every block's materials away for the sake of one.
  for (const auto& [name, value] : fills)
  {
    const int count = arrayLeaves.count(name) ? arrayLeaves[name] : 0;
    if (count == 0 || count == leaves)
    {
      continue;
    }
    vtkDataArray* model = nullptr;
    for (const auto& surface : surfaces)
    {
      model = model ? model : surface.first->GetCellData()->GetArray(name.c_str());
    }
    std::vector<std::string> filled;
    for (auto& [surface, label] : surfaces)
    {
      if (!model || surface->GetCellData()->GetAbstractArray(name.c_str()))
      {
        continue;
      }
      vtkSmartPointer<vtkDataArray> constant;
      constant.TakeReference(model->NewInstance());
      constant->SetName(name.c_str());
      constant->SetNumberOfComponents(model->GetNumberOfComponents());
      constant->SetNumberOfTuples(surface->GetNumberOfCells());
      for (int c = 0; c < model->GetNumberOfComponents(); ++c)
      {
        constant->FillComponent(c, value);
      }
      surface->GetCellData()->AddArray(constant);
      filled.push_back("'" + label + "'");
    }
    if (model)
    {
      arrayLeaves[name] = leaves;
      std::string blocks;
      for (std::size_t i = 0; i < filled.size(); ++i)
      {
        blocks += (i == 0 ? "" : ", ") + filled[i];
      }
      std::ostringstream message;
      message << "the " << port << "'s cell array '" << name << "' is on " << count << " of its "
              << leaves << " blocks with cells: the " << (filled.size() == 1 ? "block " : "blocks ")
              << blocks << " without it " << (filled.size() == 1 ? "takes " : "take ") << value
              << ": give it to every block";
      warnings.push_back(message.str());
    }
  }
  for (const auto& surface : surfaces)
  {
    append->AddInputData(surface.first);
  }
  for (const auto& [name, count] : arrayLeaves)
  {
    if (count < leaves)
    {
      warnings.push_back("the " + port + "'s cell array '" + name + "' is on " +
        std::to_string(count) + " of its " + std::to_string(leaves) +
        " blocks with cells, so it is dropped: give it to every block");
    }
  }
  append->Update();
  vtkSmartPointer<vtkPolyData> whole = append->GetOutput();
  for (const auto& [name, count] : arrayLeaves)
  {
    // vtkAppendPolyData keeps an array only where every block's has one type and width.
    if (count == leaves && !whole->GetCellData()->HasArray(name.c_str()))
    {
      warnings.push_back("the " + port + "'s cell array '" + name +
        "' is on every block, but not of one type and number of components, so it is "
        "dropped: give it one type (int, double...) and width on every block");
    }
  }
  if (materialNames->GetNumberOfValues() > 0)
  {
    whole->GetFieldData()->RemoveArray("MaterialNames");
    whole->GetFieldData()->AddArray(materialNames);
  }
  whole->GetFieldData()->AddArray(blockNames);
  return whole;
}

PolygonSoup sceneSoup(vtkPolyData* scene, std::vector<std::string>& warnings,
  std::uint64_t memoryLimitBytes, const std::string& reflectanceName,
  const std::string& emissionName, int skipMaterial)
{
  PolygonSoup soup;
  if (!scene || scene->GetNumberOfCells() == 0)
  {
    return soup;
  }
  {
    // Per point 24 bytes and 4 for its new number; per polygon its index vector (~56 bytes
    // with the allocator's overhead) and material (24), and 4 bytes per index. Strips become
    // one polygon per triangle.
    // The Scene is in memory, so these sums of its sizes cannot overflow.
    const auto count = [](vtkIdType n) { return static_cast<std::uint64_t>(n); };
    const std::uint64_t stripIds = count(scene->GetStrips()->GetNumberOfConnectivityIds());
    const std::uint64_t cells = count(scene->GetNumberOfPolys()) + stripIds;
    const std::uint64_t ids = count(scene->GetPolys()->GetNumberOfConnectivityIds()) + 3 * stripIds;
    const std::uint64_t estimate = 28 * count(scene->GetNumberOfPoints()) + 80 * cells + 4 * ids;
    MemoryBudget(memoryLimitBytes)
      .check(estimate,
        "the Scene has " + std::to_string(scene->GetNumberOfCells()) + " cells on " +
          std::to_string(scene->GetNumberOfPoints()) + " points: taking them for remeshing",
        "", "simplify the scene or raise MemoryLimit");
  }
  const vtkIdType ignored = scene->GetNumberOfVerts() + scene->GetNumberOfLines();
  if (ignored > 0)
  {
    warnings.push_back("ignored " +
      countOf(static_cast<std::size_t>(scene->GetNumberOfVerts()), "vertex", "vertices") + " and " +
      countOf(static_cast<std::size_t>(scene->GetNumberOfLines()), "line") +
      " of the Scene: only polygons and triangle strips are surfaces");
  }
  if (scene->GetNumberOfPolys() + scene->GetNumberOfStrips() == 0)
  {
    return soup;
  }

  vtkDataArray* reflectance = colourArray(scene, reflectanceName, "in [0, 1)");
  vtkDataArray* emission = colourArray(scene, emissionName, "in W/m^2, >= 0");
  if (!reflectance)
  {
    std::ostringstream s;
    s << "the Scene has no cell array "
      << (reflectanceName.empty() ? "for reflectance" : reflectanceName)
      << ": every surface is grey " << Material{}.reflectance.g
      << lookalikeOf(scene, reflectanceName, "ReflectanceArrayName");
    warnings.push_back(s.str());
  }
  if (!emission)
  {
    const std::string lookalike = lookalikeOf(scene, emissionName, "EmissionArrayName");
    if (!lookalike.empty())
    {
      warnings.push_back(
        "the Scene has no cell array " + emissionName + ": nothing in it emits" + lookalike);
    }
  }

  // Only the points that polygons use, in their order: a point no surface uses (an unused
  // point, an interior point of a volume, a vertex cell's) neither fails the solve with its
  // NaN nor stretches the scene's extent.
  const vtkIdType pointCount = scene->GetNumberOfPoints();
  constexpr std::uint32_t Unused = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> newId(static_cast<std::size_t>(pointCount), Unused);
  forEachSurfaceCell(scene,
    [&](vtkIdType cellId, const std::vector<std::uint32_t>& ids)
    {
      for (std::uint32_t id : ids)
      {
        if (id >= static_cast<std::uint64_t>(pointCount))
        {
          throw Error("Scene " + cellPlace(scene, cellId) + " uses point " + std::to_string(id) +
            " but the Scene has " + std::to_string(pointCount) + " points: fix its connectivity");
        }
        newId[id] = 0;
      }
    });
  std::size_t nonFinite = 0;
  vtkIdType firstNonFinite = -1;
  for (vtkIdType i = 0; i < pointCount; ++i)
  {
    if (newId[static_cast<std::size_t>(i)] == Unused)
    {
      continue;
    }
    double p[3];
    scene->GetPoint(i, p);
    const Vec3 point(p[0], p[1], p[2]);
    if (!isFinite(point) && nonFinite++ == 0)
    {
      firstNonFinite = i;
    }
    newId[static_cast<std::size_t>(i)] = static_cast<std::uint32_t>(soup.points.size());
    soup.points.push_back(point);
  }
  if (nonFinite > 0)
  {
    // Named with a cell that uses it, which names the block of a composite input.
    vtkIdType user = -1;
    forEachSurfaceCell(scene,
      [&](vtkIdType cellId, const std::vector<std::uint32_t>& ids)
      {
        if (user < 0 && std::find(ids.begin(), ids.end(), firstNonFinite) != ids.end())
        {
          user = cellId;
        }
      });
    double p[3];
    scene->GetPoint(firstNonFinite, p);
    std::ostringstream s;
    s << "the Scene has " << countOf(nonFinite, "point")
      << " with NaN or infinite coordinates in its polygons; the first is "
      << pointPlace(scene, firstNonFinite) << " (" << p[0] << ", " << p[1] << ", " << p[2]
      << ") of " << cellPlace(scene, user) << ": fix them or remove the cells that use them";
    throw Error(s.str());
  }

  vtkDataArray* materialIds = skipMaterial >= 0 ? materialIdArray(scene) : nullptr;
  forEachSurfaceCell(scene,
    [&](vtkIdType cellId, const std::vector<std::uint32_t>& ids)
    {
      if (materialIds && materialIds->GetComponent(cellId, 0) == skipMaterial)
      {
        return;
      }
      std::vector<std::uint32_t> polygon(ids.size());
      std::transform(
        ids.begin(), ids.end(), polygon.begin(), [&](std::uint32_t id) { return newId[id]; });
      soup.polygons.push_back(std::move(polygon));
      Material material;
      if (reflectance)
      {
        material.reflectance = reflectanceOfCell(scene, reflectance, cellId, reflectanceName);
      }
      if (emission)
      {
        material.emission = emissionOfCell(scene, emission, cellId, emissionName);
      }
      soup.materials.push_back(material);
    });
  return soup;
}

MaterialLight materialLight(
  vtkPolyData* scene, const std::string& material, const std::string& emissionName)
{
  auto* names = scene
    ? vtkStringArray::SafeDownCast(scene->GetFieldData()->GetAbstractArray("MaterialNames"))
    : nullptr;
  vtkDataArray* ids = scene ? materialIdArray(scene) : nullptr;
  if (!names || !ids)
  {
    throw Error("the Scene has no materials (field data MaterialNames and cell array "
                "MaterialId, as the radiosity scene reader gives for OBJ+MTL, glTF and PLY "
                "files), so no light can be taken from its material '" +
      material + "'");
  }
  MaterialLight result;
  std::string found;
  for (vtkIdType i = 0; i < names->GetNumberOfValues(); ++i)
  {
    if (names->GetValue(i) == material)
    {
      result.materialId = static_cast<int>(i);
    }
    found += (i > 0 ? ", '" : "'") + names->GetValue(i) + "'";
  }
  if (result.materialId < 0)
  {
    throw Error("the Scene has no material named '" + material + "': its materials are " +
      (found.empty() ? std::string("none") : found));
  }
  vtkDataArray* emission = colourArray(scene, emissionName, "in W/m^2, >= 0");
  const std::vector<Vec3> points = pointsOf(scene);
  Rgb power;
  forEachSurfaceCell(scene,
    [&](vtkIdType cellId, const std::vector<std::uint32_t>& pointIds)
    {
      if (ids->GetComponent(cellId, 0) != result.materialId)
      {
        return;
      }
      std::vector<Vec3> polygon;
      for (std::uint32_t id : pointIds)
      {
        if (id >= points.size())
        {
          throw Error("a Scene polygon uses point " + std::to_string(id) + " but the Scene has " +
            std::to_string(points.size()) + " points: fix its connectivity");
        }
        polygon.push_back(points[id]);
      }
      if (emission)
      {
        power += emissionOfCell(scene, emission, cellId, emissionName) *
          (0.5 * length(newellNormal(polygon)));
      }
      result.light.polygons.push_back(std::move(polygon));
    });
  if (result.light.polygons.empty())
  {
    throw Error("the Scene's material '" + material +
      "' has no polygon: choose a material "
      "with surfaces (its materials are " +
      found + ")");
  }
  if (power.maxComponent() > 0)
  {
    result.light.hasPower = true;
    result.light.power = power;
  }
  return result;
}

std::size_t lightCount(vtkPolyData* light)
{
  vtkDataArray* ids = lightIdArray(light);
  return ids ? std::max<std::size_t>(1, distinctLightIds(light, ids).size()) : 1;
}

std::vector<LightInput> lightInputs(vtkPolyData* light)
{
  std::vector<LightInput> lights;
  if (!light)
  {
    return lights;
  }
  vtkDataArray* ids = lightIdArray(light);
  const std::vector<long long> distinct =
    ids ? distinctLightIds(light, ids) : std::vector<long long>{ 0 };
  lights.resize(distinct.size());
  vtkDataArray* power = nullptr;
  if (vtkAbstractArray* array = light->GetCellData()->GetAbstractArray("LightPower"))
  {
    power = vtkDataArray::SafeDownCast(array);
    if (!power || (power->GetNumberOfComponents() != 3 && power->GetNumberOfComponents() != 1) ||
      power->GetNumberOfTuples() < light->GetNumberOfCells())
    {
      throw Error("the Light's cell array LightPower must be numeric with 3 components (RGB, "
                  "W) or 1 (white) per cell: fix it or remove it to use the LightPower property");
    }
  }
  const std::vector<Vec3> points = pointsOf(light);
  forEachSurfaceCell(light,
    [&](vtkIdType cellId, const std::vector<std::uint32_t>& pointIds)
    {
      std::vector<Vec3> polygon;
      polygon.reserve(pointIds.size());
      for (std::uint32_t id : pointIds)
      {
        if (id >= points.size())
        {
          throw Error("a Light polygon uses point " + std::to_string(id) + " but the Light has " +
            std::to_string(points.size()) + " points: fix its connectivity");
        }
        polygon.push_back(points[id]);
      }
      const std::size_t which = ids
        ? static_cast<std::size_t>(std::lower_bound(distinct.begin(), distinct.end(),
                                     static_cast<long long>(ids->GetComponent(cellId, 0))) -
            distinct.begin())
        : 0;
      LightInput& target = lights[which];
      target.polygons.push_back(std::move(polygon));
      if (power)
      {
        const Rgb p = colourOfCell(power, cellId);
        if (target.hasPower && p != target.power)
        {
          throw Error("the Light's cell array LightPower differs between the polygons of light " +
            std::to_string(distinct[which]) + ": give every polygon of a light the same power");
        }
        target.power = p;
        target.hasPower = true;
      }
    });
  for (std::size_t i = 0; i < lights.size(); ++i)
  {
    if (lights[i].polygons.empty())
    {
      throw Error((ids ? "light " + std::to_string(distinct[i]) + " of the Light"
                       : std::string("the light")) +
        " has no polygon (only vertices or lines): give at least one polygon with 3 or more "
        "points");
    }
  }
  return lights;
}

namespace
{
/// The inputs of the points `ids` of the trajectory, one per point.
std::vector<PoseInput> poseInputsOf(vtkPointSet* trajectory, const std::vector<vtkIdType>& ids)
{
  vtkDataArray* normal = pointArray(trajectory, "Normal", 3);
  vtkDataArray* orientation = pointArray(trajectory, "Orientation", 4);
  vtkDataArray* power = pointArray(trajectory, "Power", 1, 3);
  std::vector<PoseInput> inputs(ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i)
  {
    const vtkIdType id = ids[i];
    PoseInput& in = inputs[i];
    double p[3];
    trajectory->GetPoint(id, p);
    in.position = { p[0], p[1], p[2] };
    if (normal)
    {
      in.hasNormal = true;
      in.normal = { normal->GetComponent(id, 0), normal->GetComponent(id, 1),
        normal->GetComponent(id, 2) };
    }
    if (orientation)
    {
      in.hasOrientation = true;
      for (int c = 0; c < 4; ++c)
      {
        in.orientation[static_cast<std::size_t>(c)] = orientation->GetComponent(id, c);
      }
    }
    if (power)
    {
      in.power = power->GetNumberOfComponents() == 1
        ? Rgb(power->GetComponent(id, 0))
        : Rgb(power->GetComponent(id, 0), power->GetComponent(id, 1), power->GetComponent(id, 2));
      if (!in.power.isFinite() || in.power.minComponent() < 0)
      {
        std::ostringstream s;
        s << "the Trajectory's point array Power has (" << in.power.r << ", " << in.power.g << ", "
          << in.power.b << ") at point " << id
          << ": a power factor must be finite and >= 0 (0 turns the light off)";
        throw Error(s.str());
      }
    }
  }
  return inputs;
}

/// The times of the points `ids`, from the point array Time, or 0, 1, ...
/// The per-frame point arrays of the points `ids` (one per frame) into `result`.
void perFrameArrays(vtkPointSet* trajectory, const std::vector<vtkIdType>& ids, Trajectory& result)
{
  const std::pair<const char*, std::vector<double>*> arrays[] = {
    { "SunAzimuth", &result.sunAzimuth }, { "SunElevation", &result.sunElevation },
    { "SkyDiffuseHorizontal", &result.skyDiffuseHorizontal },
    { "DirectNormalIrradiance", &result.directNormal }
  };
  for (const auto& [name, into] : arrays)
  {
    if (vtkDataArray* values = pointArray(trajectory, name, 1))
    {
      for (vtkIdType id : ids)
      {
        into->push_back(values->GetComponent(id, 0));
      }
    }
  }
  if (vtkDataArray* days = pointArray(trajectory, "DayOfYear", 1))
  {
    for (vtkIdType id : ids)
    {
      const double day = days->GetComponent(id, 0);
      if (!(day >= 1 && day <= 366) || day != std::floor(day))
      {
        std::ostringstream s;
        s << "the Trajectory's point array DayOfYear has " << day << " at point " << id
          << ": give whole days from 1 (January 1) to 366, or remove the array";
        throw Error(s.str());
      }
      result.dayOfYear.push_back(static_cast<int>(day));
    }
  }
}

std::vector<double> timesOf(vtkPointSet* trajectory, const std::vector<vtkIdType>& ids)
{
  const std::size_t n = ids.size();
  std::vector<double> result(n);
  vtkAbstractArray* array = trajectory->GetPointData()->GetAbstractArray("Time");
  if (!array)
  {
    for (std::size_t i = 0; i < n; ++i)
    {
      result[i] = static_cast<double>(i);
    }
    return result;
  }
  auto* times = vtkDataArray::SafeDownCast(array);
  if (!times || times->GetNumberOfComponents() != 1 ||
    times->GetNumberOfTuples() != trajectory->GetNumberOfPoints())
  {
    throw Error("the Trajectory's point array Time must be numeric with one value per point (" +
      std::to_string(trajectory->GetNumberOfPoints()) +
      "): fix it or remove it to number the frames 0, 1, ...");
  }
  for (std::size_t i = 0; i < n; ++i)
  {
    const double t = times->GetComponent(ids[i], 0);
    if (!std::isfinite(t) || (i > 0 && !(t > result[i - 1])))
    {
      std::ostringstream s;
      s << "the Trajectory's point array Time must increase strictly with finite values: "
        << "point " << ids[i] << " has time " << t;
      if (i > 0)
      {
        s << " after " << result[i - 1];
      }
      throw Error(s.str());
    }
    result[i] = t;
  }
  return result;
}
}

Trajectory trajectoryFromPoints(vtkPointSet* trajectory, std::size_t lights)
{
  const vtkIdType n = trajectory && trajectory->GetPoints() ? trajectory->GetNumberOfPoints() : 0;
  if (n == 0)
  {
    throw Error("the Trajectory has no points: give one point per light position, or "
                "disconnect it to move the light from PathStart to PathEnd");
  }
  // The point ids of each light's positions.
  std::vector<std::vector<vtkIdType>> perLight;
  auto* poly = vtkPolyData::SafeDownCast(trajectory);
  const vtkIdType lines = poly ? poly->GetNumberOfLines() : 0;
  if (lights <= 1 && lines > 1)
  {
    // One light would run through every polyline's points in turn, as if they were frames:
    // the second light that was meant never appears.
    throw Error("the Trajectory has " + std::to_string(lines) +
      " polylines but it moves one light (a point light, a luminaire, the sun, a "
      "LightMaterial or a Light whose cell array LightId has one value or none), which takes "
      "one polyline "
      "(or points, one per frame): join them into one, or give several area lights a Light "
      "cell array LightId (one value per light) with one polyline per light in LightId "
      "order; point lights are solved one at a time (their Irradiance arrays add up)");
  }
  if (lights <= 1)
  {
    perLight.emplace_back(static_cast<std::size_t>(n));
    for (vtkIdType i = 0; i < n; ++i)
    {
      perLight[0][static_cast<std::size_t>(i)] = i;
    }
  }
  else
  {
    if (static_cast<std::size_t>(lines) != lights)
    {
      throw Error("the Light holds " + std::to_string(lights) +
        " lights (LightId) but the Trajectory has " +
        countOf(static_cast<std::size_t>(lines), "polyline") +
        ": give one polyline per light, in LightId order (a single point for a light that "
        "does not move)");
    }
    auto it = vtkSmartPointer<vtkCellArrayIterator>::Take(poly->GetLines()->NewIterator());
    for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell())
    {
      vtkIdType count = 0;
      const vtkIdType* ids = nullptr;
      it->GetCurrentCell(count, ids);
      if (count == 0)
      {
        throw Error("polyline " + std::to_string(perLight.size()) +
          " of the Trajectory has no point: give each light at least one");
      }
      perLight.emplace_back(ids, ids + count);
    }
  }

  Trajectory result;
  std::size_t frames = 0;
  std::size_t firstMoving = 0;
  for (std::size_t l = 0; l < perLight.size(); ++l)
  {
    const std::size_t count = perLight[l].size();
    if (count > 1 && frames == 0)
    {
      frames = count;
      firstMoving = l;
      result.times = timesOf(trajectory, perLight[l]);
      perFrameArrays(trajectory, perLight[l], result);
    }
    else if (count > 1 && count != frames)
    {
      throw Error("polyline " + std::to_string(l) + " of the Trajectory has " +
        std::to_string(count) + " points but polyline " + std::to_string(firstMoving) + " has " +
        std::to_string(frames) +
        ": every moving light needs one point per frame (one point: a light that does not move)");
    }
    result.lights.push_back(poseInputsOf(trajectory, perLight[l]));
  }
  if (frames == 0)
  {
    result.times = timesOf(trajectory, { perLight[0].front() });
    perFrameArrays(trajectory, { perLight[0].front() }, result);
  }
  return result;
}

Trajectory straightTrajectory(const Vec3& start, const Vec3& end, int count)
{
  Trajectory result;
  const int n = std::max(count, 1);
  result.lights.emplace_back();
  for (int i = 0; i < n; ++i)
  {
    const double s = n > 1 ? static_cast<double>(i) / (n - 1) : 0.0;
    PoseInput in;
    in.position = start + (end - start) * s;
    result.lights[0].push_back(in);
    result.times.push_back(static_cast<double>(i));
  }
  return result;
}

std::size_t frameAtOrBelow(const std::vector<double>& times, double time)
{
  if (times.empty())
  {
    return 0;
  }
  const auto above = std::upper_bound(times.begin(), times.end(), time);
  const std::size_t next = static_cast<std::size_t>(above - times.begin());
  if (next < times.size())
  {
    // A request a rounding below a step lands on it: a time keeper's arithmetic, or a step
    // given in single precision (a float Time array's 0.2 is 0.2000000030) asked for as
    // written. The rounding is a few float steps of the time, or of the range near 0, and
    // never a quarter of the way to the step before.
    const double range = std::max(1.0, std::abs(times.back() - times.front()));
    const double rounding =
      0x1.0p-20 * std::max(std::abs(times[next]), std::abs(time)) + 1e-9 * range;
    const double gap = next > 0 ? times[next] - times[next - 1] : rounding;
    if (times[next] - time <= std::min(rounding, 0.25 * gap))
    {
      return next;
    }
  }
  return next == 0 ? 0 : next - 1;
}

} // namespace mlr::vtkinputs
