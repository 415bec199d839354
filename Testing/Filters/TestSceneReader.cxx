// vtkRadiositySceneReader: materials from OBJ+MTL, glTF and PLY files written here,
// the same reflectances from every format, and bad input with an error naming the file.
#include "FilterTestSupport.h"

#include "vtkCallbackCommand.h"
#include "vtkCell.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkExecutive.h"
#include "vtkFieldData.h"
#include "vtkIdList.h"
#include "vtkImageData.h"
#include "vtkJPEGWriter.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkRadiositySceneReader.h"
#include "vtkSmartPointer.h"
#include "vtkStringArray.h"
#include "vtkUnsignedCharArray.h"
#include "vtkXMLPolyDataReader.h"
#include "vtkXMLPolyDataWriter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace mlr::testing;

namespace
{
namespace fs = std::filesystem;
constexpr double Pi = 3.14159265358979323846;

void writeFile(const fs::path& path, const std::string& text)
{
  std::ofstream out(path, std::ios::binary);
  out << text;
}

struct ReadResult
{
  bool succeeded = false;
  vtkSmartPointer<vtkPolyData> output;
  vtkSmartPointer<MessageRecorder> messages;
  std::string errors() const { return this->messages->allErrors(); }
  std::string warnings() const { return this->messages->allWarnings(); }
};

ReadResult readScene(const fs::path& path)
{
  ReadResult result;
  auto reader = vtkSmartPointer<vtkRadiositySceneReader>::New();
  reader->SetFileName(path.string().c_str());
  result.messages = vtkSmartPointer<MessageRecorder>::New();
  result.messages->watch(reader);
  result.succeeded = reader->GetExecutive()->Update() != 0;
  result.output = reader->GetOutput();
  return result;
}

std::array<double, 3> tuple3(vtkPolyData* mesh, const char* name, vtkIdType cell)
{
  vtkDataArray* array = mesh->GetCellData()->GetArray(name);
  std::array<double, 3> value{ { NAN, NAN, NAN } };
  if (array && array->GetNumberOfComponents() == 3 && cell < array->GetNumberOfTuples())
  {
    array->GetTuple(cell, value.data());
  }
  return value;
}

std::vector<std::string> materialNames(vtkPolyData* mesh)
{
  std::vector<std::string> names;
  auto* array =
    vtkStringArray::SafeDownCast(mesh->GetFieldData()->GetAbstractArray("MaterialNames"));
  for (vtkIdType i = 0; array && i < array->GetNumberOfValues(); ++i)
  {
    names.push_back(array->GetValue(i));
  }
  return names;
}

std::string stringField(vtkPolyData* mesh, const char* name)
{
  auto* array = vtkStringArray::SafeDownCast(mesh->GetFieldData()->GetAbstractArray(name));
  return array && array->GetNumberOfValues() == 1 ? array->GetValue(0) : std::string();
}

int materialId(vtkPolyData* mesh, vtkIdType cell)
{
  vtkDataArray* array = mesh->GetCellData()->GetArray("MaterialId");
  return array ? static_cast<int>(array->GetComponent(cell, 0)) : -1;
}

void expectRgbNear(const std::array<double, 3>& actual, double r, double g, double b,
  double tolerance, const std::string& context = "")
{
  SCOPED_TRACE(context);
  EXPECT_NEAR(actual[0], r, tolerance);
  EXPECT_NEAR(actual[1], g, tolerance);
  EXPECT_NEAR(actual[2], b, tolerance);
}

// --- The two-material scene every format describes ------------------------------------------
// A white floor (z = 0) and a red wall (x = 0), one unit square each, two triangles each.
const double White[3] = { 0.725, 0.71, 0.68 };
const double Red[3] = { 0.63, 0.065, 0.05 };
const float Corners[8][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 }, // floor
  { 0, 0, 0 }, { 0, 1, 0 }, { 0, 1, 1 }, { 0, 0, 1 } };                           // wall
const std::uint16_t Triangles[4][3] = { { 0, 1, 2 }, { 0, 2, 3 }, { 4, 5, 6 }, { 4, 6, 7 } };

void expectTwoMaterialScene(vtkPolyData* mesh, double tolerance)
{
  ASSERT_EQ(mesh->GetNumberOfCells(), 4);
  for (vtkIdType cell = 0; cell < 4; ++cell)
  {
    const double* kd = cell < 2 ? White : Red;
    expectRgbNear(tuple3(mesh, "Reflectance", cell), kd[0], kd[1], kd[2], tolerance,
      "cell " + std::to_string(cell));
    expectRgbNear(tuple3(mesh, "Emission", cell), 0, 0, 0, 0);
  }
}

std::string base64(const std::string& bytes)
{
  static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string text;
  for (std::size_t i = 0; i < bytes.size(); i += 3)
  {
    std::uint32_t chunk = static_cast<std::uint8_t>(bytes[i]) << 16;
    chunk |= i + 1 < bytes.size() ? static_cast<std::uint8_t>(bytes[i + 1]) << 8 : 0;
    chunk |= i + 2 < bytes.size() ? static_cast<std::uint8_t>(bytes[i + 2]) : 0;
    text += alphabet[(chunk >> 18) & 63];
    text += alphabet[(chunk >> 12) & 63];
    text += i + 1 < bytes.size() ? alphabet[(chunk >> 6) & 63] : '=';
    text += i + 2 < bytes.size() ? alphabet[chunk & 63] : '=';
  }
  return text;
}

/// The buffer of the glTF scene: 8 float positions, then 12 uint16 indices.
std::string gltfBuffer()
{
  std::string bytes(sizeof(Corners) + sizeof(Triangles), '\0');
  std::memcpy(bytes.data(), Corners, sizeof(Corners));
  std::memcpy(bytes.data() + sizeof(Corners), Triangles, sizeof(Triangles));
  return bytes;
}

/// The glTF JSON of the two-material scene: one mesh, a primitive per material, under a node
/// translated by `translation`. `bufferUri` empty: the .glb BIN chunk.
std::string gltfJson(const std::string& bufferUri, const std::string& extra = "",
  const std::string& translation = "[0, 0, 0]", int mode = 4)
{
  const std::string uri = bufferUri.empty() ? "" : R"("uri": ")" + bufferUri + R"(", )";
  return R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [{"translation": )" +
    translation + R"(, "children": [1]}, {"mesh": 0}],
  "meshes": [{"primitives": [
    {"attributes": {"POSITION": 0}, "indices": 1, "material": 0, "mode": )" +
    std::to_string(mode) + R"(},
    {"attributes": {"POSITION": 0}, "indices": 2, "material": 1, "mode": )" +
    std::to_string(mode) + R"(}]}],
  "materials": [
    {"name": "white", "pbrMetallicRoughness": {"baseColorFactor": [0.725, 0.71, 0.68, 1]}},
    {"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [0.63, 0.065, 0.05, 1]}}],
  "buffers": [{)" +
    uri + R"("byteLength": 120}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 96},
    {"buffer": 0, "byteOffset": 96, "byteLength": 24}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
     "min": [0, 0, 0], "max": [1, 1, 1]},
    {"bufferView": 1, "byteOffset": 0, "componentType": 5123, "count": 6, "type": "SCALAR"},
    {"bufferView": 1, "byteOffset": 12, "componentType": 5123, "count": 6, "type": "SCALAR"}])" +
    extra + "\n}\n";
}

/// Replaces the first `from` in `text` (which must hold it) by `to`.
void replaceOnce(std::string& text, const std::string& from, const std::string& to)
{
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
}

std::string dataUri(const std::string& bytes)
{
  return "data:application/octet-stream;base64," + base64(bytes);
}

void put32(std::string& out, std::uint32_t value)
{
  for (int i = 0; i < 4; ++i)
  {
    out += static_cast<char>((value >> (8 * i)) & 0xff);
  }
}

std::string glbFile(std::string json, std::string bin)
{
  while (json.size() % 4)
  {
    json += ' ';
  }
  while (bin.size() % 4)
  {
    bin += '\0';
  }
  std::string out = "glTF";
  put32(out, 2);
  put32(out, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
  put32(out, static_cast<std::uint32_t>(json.size()));
  out += "JSON" + json;
  put32(out, static_cast<std::uint32_t>(bin.size()));
  out += std::string("BIN\0", 4) + bin;
  return out;
}

std::string twoMaterialObj(const std::string& mtllib)
{
  std::string text = mtllib.empty() ? "" : "mtllib " + mtllib + "\n";
  for (const auto& corner : Corners)
  {
    text += "v " + std::to_string(corner[0]) + " " + std::to_string(corner[1]) + " " +
      std::to_string(corner[2]) + "\n";
  }
  return text + "usemtl white\nf 1 2 3\nf 1 3 4\nusemtl red\nf 5 6 7\nf 5 7 8\n";
}
} // namespace

// --- OBJ + MTL --------------------------------------------------------------------------------

TEST(SceneReader, ObjMaterialsGiveReflectanceEmissionAndIds)
{
  const TestFolder scratch("obj");
  const fs::path& folder = scratch.path;
  writeFile(folder / "room.mtl", R"(# two reflectors, a lamp and a glowing panel
newmtl white
Kd 0.725 0.71 0.68
Ka 0 0 0
newmtl red
Kd 0.63 0.065 0.05
newmtl light
Kd 0.78 0.78 0.78
Ke 17 12 4
newmtl glow
Kd 0.2
Ke 0.5 0.25 0.125
)");
  // The first face after each usemtl has no texture or normal indices (VTK 9.2's vtkOBJReader
  // gives those NO_MATERIAL); others use v/vt/vn, v//vn, negative indices and a continuation.
  writeFile(folder / "room.obj", R"(mtllib room.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vn 0 0 1
usemtl white
f 1 2 3
f 1/1/1 3/1/1 4/1/1
usemtl red
f 1 4 \
  3
v 0.4 0.4 0.99
v 0.6 0.4 0.99
v 0.6 0.6 0.99
v 0.4 0.6 0.99
usemtl light
f -1 -2 -3 -4
usemtl glow
f 1//1 2//1 3//1
usemtl white
f 4 3 2
)");
  const ReadResult result = readScene(folder / "room.obj");
  ASSERT_TRUE(result.succeeded) << result.errors();
  EXPECT_EQ(result.errors(), "");
  EXPECT_EQ(result.warnings(), "");
  vtkPolyData* mesh = result.output;
  ASSERT_EQ(mesh->GetNumberOfPoints(), 8);
  ASSERT_EQ(mesh->GetNumberOfCells(), 6);
  EXPECT_EQ(mesh->GetCell(3)->GetNumberOfPoints(), 4);
  EXPECT_EQ(materialNames(mesh), (std::vector<std::string>{ "white", "red", "light", "glow" }));
  const int expectedIds[6] = { 0, 0, 1, 2, 3, 0 };
  for (vtkIdType cell = 0; cell < 6; ++cell)
  {
    EXPECT_EQ(materialId(mesh, cell), expectedIds[cell]) << "cell " << cell;
  }
  expectRgbNear(tuple3(mesh, "Reflectance", 0), 0.725, 0.71, 0.68, 1e-12);
  expectRgbNear(tuple3(mesh, "Reflectance", 1), 0.725, 0.71, 0.68, 1e-12);
  expectRgbNear(tuple3(mesh, "Reflectance", 2), 0.63, 0.065, 0.05, 1e-12);
  expectRgbNear(tuple3(mesh, "Reflectance", 3), 0.78, 0.78, 0.78, 1e-12);
  expectRgbNear(tuple3(mesh, "Reflectance", 4), 0.2, 0.2, 0.2, 1e-12);
  expectRgbNear(tuple3(mesh, "Reflectance", 5), 0.725, 0.71, 0.68, 1e-12);
  // Ke is radiance: the exitance is pi x Ke, so the lamp emits pi x Ke x area watts.
  for (vtkIdType cell : { 0, 1, 2, 5 })
  {
    expectRgbNear(tuple3(mesh, "Emission", cell), 0, 0, 0, 0, "cell " + std::to_string(cell));
  }
  expectRgbNear(tuple3(mesh, "Emission", 3), 17 * Pi, 12 * Pi, 4 * Pi, 1e-9);
  expectRgbNear(tuple3(mesh, "Emission", 4), 0.5 * Pi, 0.25 * Pi, 0.125 * Pi, 1e-12);
  const double lampArea = triangleArea(mesh, 3); // 0.2 m square: 0.04 m^2 (first triangle: half)
  EXPECT_NEAR(lampArea, 0.02, 1e-9);
  EXPECT_EQ(stringField(mesh, "EmissionUnits"), "W/m^2");
  EXPECT_EQ(stringField(mesh, "SceneFormat"), "OBJ");
}

TEST(SceneReader, ReflectanceOfOneIsClampedWithAWarningNamingTheMaterial)
{
  const TestFolder scratch("clamp");
  const fs::path& folder = scratch.path;
  writeFile(folder / "scene.mtl", "newmtl paper\nKd 1 1 1\nnewmtl red\nKd 0.63 0.065 0.05\n");
  writeFile(folder / "scene.obj",
    "mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl paper\nf 1 2 3\nusemtl red\nf 1 3 2\n");
  const ReadResult result = readScene(folder / "scene.obj");
  ASSERT_TRUE(result.succeeded) << result.errors();
  expectRgbNear(tuple3(result.output, "Reflectance", 0), 0.99, 0.99, 0.99, 1e-12);
  expectRgbNear(tuple3(result.output, "Reflectance", 1), 0.63, 0.065, 0.05, 1e-12);
  ASSERT_EQ(result.messages->warnings.size(), 1u) << result.warnings();
  EXPECT_NE(result.warnings().find("'paper'"), std::string::npos) << result.warnings();
  EXPECT_NE(result.warnings().find("clamped to 0.99"), std::string::npos) << result.warnings();
}

TEST(SceneReader, MissingMtlFallsBackToGreyWithAWarningNamingTheFile)
{
  const TestFolder scratch("missing-mtl");
  const fs::path& folder = scratch.path;
  writeFile(folder / "scene.obj", twoMaterialObj("absent.mtl"));
  const ReadResult result = readScene(folder / "scene.obj");
  ASSERT_TRUE(result.succeeded) << result.errors();
  EXPECT_EQ(result.errors(), "");
  EXPECT_NE(result.warnings().find((folder / "absent.mtl").string()), std::string::npos)
    << result.warnings();
  EXPECT_NE(result.warnings().find("grey 0.5"), std::string::npos) << result.warnings();
  ASSERT_EQ(result.output->GetNumberOfCells(), 4);
  for (vtkIdType cell = 0; cell < 4; ++cell)
  {
    expectRgbNear(tuple3(result.output, "Reflectance", cell), 0.5, 0.5, 0.5, 0);
  }
  EXPECT_EQ(materialNames(result.output), (std::vector<std::string>{ "white", "red" }));
}

TEST(SceneReader, ObjWrittenOnWindowsKeepsItsFirstLineAndFindsItsLibrary)
{
  // Notepad's byte order mark, CRLF line ends, and the library in a subfolder named with a
  // backslash: a mark left in shifted every vertex index after a first 'v' line (a tilted
  // quad of area 1.225 for the unit square) and hid a first 'newmtl'.
  const TestFolder scratch("windows-obj");
  const fs::path& folder = scratch.path;
  fs::create_directories(folder / "mats");
  const std::string mark = "\xEF\xBB\xBF";
  writeFile(folder / "mats" / "scene.mtl",
    mark + "newmtl white\r\nKd 0.725 0.71 0.68\r\nnewmtl red\r\nKd 0.63 0.065 0.05\r\n");
  std::string obj = twoMaterialObj("mats\\scene.mtl");
  // The vertices first, the library after them: the mark sits on a 'v' line.
  const std::size_t firstVertex = obj.find("v ");
  obj = mark + obj.substr(firstVertex, obj.find("usemtl") - firstVertex) +
    obj.substr(0, firstVertex) + obj.substr(obj.find("usemtl"));
  std::string crlf;
  for (char c : obj)
  {
    crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  }
  writeFile(folder / "scene.obj", crlf);
  const ReadResult result = readScene(folder / "scene.obj");
  ASSERT_TRUE(result.succeeded) << result.errors();
  EXPECT_EQ(result.warnings(), "");
  ASSERT_EQ(result.output->GetNumberOfCells(), 4);
  double first[3];
  result.output->GetPoint(0, first);
  for (int axis = 0; axis < 3; ++axis)
  {
    EXPECT_EQ(first[axis], Corners[0][axis]) << axis;
  }
  expectRgbNear(tuple3(result.output, "Reflectance", 0), 0.725, 0.71, 0.68, 1e-12);
  expectRgbNear(tuple3(result.output, "Reflectance", 3), 0.63, 0.065, 0.05, 1e-12);
}

TEST(SceneReader, ObjOrMtlInUtf16IsRefusedSayingSo)
{
  // Notepad's and PowerShell's "Unicode" is UTF-16 with a byte order mark (assimp's test model
  // box_UTF16BE.obj): read as bytes, no line has a keyword, and the error said the file had
  // no faces; an MTL in UTF-16 left every material grey without a word.
  const TestFolder scratch("utf16");
  const fs::path& folder = scratch.path;
  auto utf16 = [](const std::string& text, bool bigEndian)
  {
    std::string out = bigEndian ? "\xfe\xff" : "\xff\xfe";
    for (const char c : text)
    {
      out += bigEndian ? std::string{ '\0', c } : std::string{ c, '\0' };
    }
    return out;
  };
  const std::string mtl = "newmtl white\nKd 0.725 0.71 0.68\nnewmtl red\nKd 0.63 0.065 0.05\n";
  writeFile(folder / "be.obj", utf16(twoMaterialObj("scene.mtl"), true));
  writeFile(folder / "le.obj", utf16(twoMaterialObj("scene.mtl"), false));
  writeFile(folder / "scene.mtl", utf16(mtl, false));
  writeFile(folder / "utf8.obj", twoMaterialObj("scene.mtl"));
  for (const char* name : { "be.obj", "le.obj", "utf8.obj" })
  {
    SCOPED_TRACE(name);
    const ReadResult result = readScene(folder / name);
    EXPECT_FALSE(result.succeeded);
    const std::string expected = std::string(name) == "utf8.obj"
      ? "the material library '" + (folder / "scene.mtl").string() + "' of the OBJ file '" +
        (folder / name).string() + "' is UTF-16 text: save it as UTF-8"
      : "the OBJ file '" + (folder / name).string() + "' is UTF-16 text: save it as UTF-8";
    EXPECT_NE(result.errors().find(expected), std::string::npos) << result.errors();
  }
}

TEST(SceneReader, ObjMaterialNamesWithAHashAreKeptWhole)
{
  // 3ds Max names materials "Material #25", and assimp's OBJ exporter writes such names as
  // they are. Cut at the '#' as a comment, "Material #1" and "Material #2" were both
  // "Material": one colour for both, a warning that it was defined again. Elsewhere a '#'
  // still starts a comment.
  const TestFolder scratch("hash-names");
  const fs::path& folder = scratch.path;
  writeFile(folder / "scene #1.mtl",
    "# 3ds Max\nnewmtl Material #1\nKd 0.725 0.71 0.68 # white\nnewmtl Material #2\n"
    "Kd 0.63 0.065 0.05\n");
  std::string obj = twoMaterialObj("scene #1.mtl");
  replaceOnce(obj, "usemtl white\n", "usemtl Material #1\n");
  replaceOnce(obj, "usemtl red\n", "usemtl Material #2\n# usemtl Material #1\n");
  replaceOnce(obj, "f 5 6 7\n", "f 5 6 7 # the wall\n");
  writeFile(folder / "scene.obj", obj);
  const ReadResult result = readScene(folder / "scene.obj");
  ASSERT_TRUE(result.succeeded) << result.errors();
  expectTwoMaterialScene(result.output, 1e-12);
  EXPECT_EQ(
    materialNames(result.output), (std::vector<std::string>{ "Material #1", "Material #2" }));
  EXPECT_EQ(result.warnings(), "");

  // A '#' that starts a trailing comment on such a line still reads: names that differ as
  // they are match before it (with a warning), and a file is looked for without it.
  writeFile(folder / "commented.mtl",
    "newmtl white # the floor\nKd 0.725 0.71 0.68\nnewmtl red\nKd 0.63 0.065 0.05\n");
  std::string commented = twoMaterialObj("commented.mtl # materials");
  replaceOnce(commented, "usemtl red\n", "usemtl red # the wall\n");
  writeFile(folder / "commented.obj", commented);
  const ReadResult trailing = readScene(folder / "commented.obj");
  ASSERT_TRUE(trailing.succeeded) << trailing.errors();
  expectTwoMaterialScene(trailing.output, 1e-12);
  EXPECT_NE(trailing.warnings().find("'white # the floor' is used"), std::string::npos)
    << trailing.warnings();
  EXPECT_NE(trailing.warnings().find("the material 'red # the wall'"), std::string::npos)
    << trailing.warnings();
}

TEST(SceneReader, ObjMaterialsWithoutFacesAreLeftOut)
{
  // Exporters write a 'usemtl' per material slot, some with no face after it (tinyobjloader's
  // cornell_box.obj, 'blue'): such a material is not in MaterialNames, its ids do not move
  // the others', and its Kd of 1.2 is not warned of.
  const TestFolder scratch("unused-materials");
  const fs::path& folder = scratch.path;
  writeFile(folder / "scene.mtl",
    "newmtl white\nKd 0.725 0.71 0.68\nnewmtl red\nKd 0.63 0.065 0.05\nnewmtl blue\n"
    "Kd 1.2 1.2 1.2\n");
  std::string obj = twoMaterialObj("scene.mtl");
  replaceOnce(obj, "usemtl white\n", "usemtl blue\nusemtl white\n");
  obj += "usemtl blue\n";
  writeFile(folder / "scene.obj", obj);
  const ReadResult result = readScene(folder / "scene.obj");
  ASSERT_TRUE(result.succeeded) << result.errors();
  expectTwoMaterialScene(result.output, 1e-12);
  EXPECT_EQ(materialNames(result.output), (std::vector<std::string>{ "white", "red" }));
  EXPECT_EQ(result.warnings(), "");
}

TEST(SceneReader, ObjVertexColoursAreTheFacesReflectance)
{
  // MeshLab writes 'v x y z r g b'. A face whose vertices all have a colour reflects their
  // mean times its material's Kd (1 without one), clamped once; a face with an uncoloured
  // vertex keeps its material's reflectance.
  const TestFolder scratch("vertex-colours");
  const fs::path& folder = scratch.path;
  writeFile(folder / "alone.obj",
    "v 0 0 0 0.2 0.4 0.6\nv 1 0 0 0.2 0.4 0.6\nv 1 1 0 0.5 0.1 0.9\nv 0 1 0\n"
    "f 1 2 3\nf 1 3 4\n");
  const ReadResult alone = readScene(folder / "alone.obj");
  ASSERT_TRUE(alone.succeeded) << alone.errors();
  ASSERT_EQ(alone.output->GetNumberOfCells(), 2);
  expectRgbNear(tuple3(alone.output, "Reflectance", 0), 0.3, 0.3, 0.7, 1e-12, "coloured");
  expectRgbNear(tuple3(alone.output, "Reflectance", 1), 0.5, 0.5, 0.5, 1e-12, "uncoloured");

  writeFile(folder / "bright.mtl", "newmtl bright\nKd 2 1 0.5\n");
  writeFile(folder / "bright.obj",
    "mtllib bright.mtl\nv 0 0 0 0.4 0.4 0.4\nv 1 0 0 0.4 0.4 0.4\nv 1 1 0 0.4 0.4 0.4\n"
    "usemtl bright\nf 1 2 3\n");
  const ReadResult bright = readScene(folder / "bright.obj");
  ASSERT_TRUE(bright.succeeded) << bright.errors();
  expectRgbNear(tuple3(bright.output, "Reflectance", 0), 0.8, 0.4, 0.2, 1e-12, "Kd x colour");

  writeFile(folder / "bad.obj", "v 0 0 0 0.2 0.4 1.5\nv 1 0 0\nv 1 1 0\nf 1 2 3\n");
  const ReadResult bad = readScene(folder / "bad.obj");
  EXPECT_FALSE(bad.succeeded);
  EXPECT_NE(
    bad.errors().find("has a colour r g b that is not 3 numbers from 0 to 1"), std::string::npos)
    << bad.errors();
}

TEST(SceneReader, ObjMaterialsThatLetLightThroughAreWarnedOfAndReadAsOpaque)
{
  const TestFolder scratch("see-through");
  const fs::path& folder = scratch.path;
  writeFile(folder / "scene.mtl",
    "newmtl white\nKd 0.7\nd 1\nTr 1\nnewmtl red\nKd 0.6 0.1 0.1\nd -halo 0.3\n"
    "newmtl tinted\nKd 0.5\nTr 0.25\n");
  writeFile(folder / "scene.obj", twoMaterialObj("scene.mtl"));
  const ReadResult result = readScene(folder / "scene.obj");
  ASSERT_TRUE(result.succeeded) << result.errors();
  EXPECT_NE(result.warnings().find("has 2 materials that let light through (d below 1, or Tr): "
                                   "'red', 'tinted'; they are read as opaque"),
    std::string::npos)
    << result.warnings();
  expectRgbNear(tuple3(result.output, "Reflectance", 3), 0.6, 0.1, 0.1, 1e-12);
}

TEST(SceneReader, MaterialMissingFromTheMtlIsGreyWithAWarningNamingIt)
{
  const TestFolder scratch("undefined-material");
  const fs::path& folder = scratch.path;
  writeFile(folder / "scene.mtl", "newmtl white\nKd 0.725 0.71 0.68\n");
  writeFile(folder / "scene.obj", twoMaterialObj("scene.mtl"));
  const ReadResult result = readScene(folder / "scene.obj");
  ASSERT_TRUE(result.succeeded) << result.errors();
  EXPECT_NE(result.warnings().find("'red'"), std::string::npos) << result.warnings();
  expectRgbNear(tuple3(result.output, "Reflectance", 0), 0.725, 0.71, 0.68, 1e-12);
  expectRgbNear(tuple3(result.output, "Reflectance", 3), 0.5, 0.5, 0.5, 0);
}

TEST(SceneReader, ObjBareUsemtlGivesTheDefaultMaterialWithAWarning)
{
  // Rhino writes a 'usemtl' without a name for faces without a material.
  const TestFolder scratch("bare-usemtl");
  const fs::path& folder = scratch.path;
  writeFile(
    folder / "scene.mtl", "newmtl white\nKd 0.725 0.71 0.68\nnewmtl red\nKd 0.63 0.065 0.05\n");
  std::string obj = twoMaterialObj("scene.mtl");
  replaceOnce(obj, "usemtl red\n", "usemtl\n");
  writeFile(folder / "scene.obj", obj);
  const ReadResult result = readScene(folder / "scene.obj");
  ASSERT_TRUE(result.succeeded) << result.errors();
  EXPECT_NE(result.warnings().find("line 13: 'usemtl' without a material name"), std::string::npos)
    << result.warnings();
  expectRgbNear(tuple3(result.output, "Reflectance", 0), 0.725, 0.71, 0.68, 1e-12);
  expectRgbNear(tuple3(result.output, "Reflectance", 3), 0.5, 0.5, 0.5, 0);
  EXPECT_EQ(materialNames(result.output), (std::vector<std::string>{ "white", "none" }));
}

TEST(SceneReader, ObjBareUsemtlTakesTheUnnamedMaterialOfItsLibrary)
{
  // Blender writes a material slot without a name as 'newmtl' without a name in the MTL and
  // 'usemtl' without a name in the OBJ (assimp's test model empty_mat.obj): the faces take
  // that material. The whole file was refused ('newmtl' without a material name).
  const TestFolder scratch("unnamed-newmtl");
  const fs::path& folder = scratch.path;
  writeFile(folder / "scene.mtl",
    "# Blender MTL File: ''\nnewmtl white\nKd 0.725 0.71 0.68\nnewmtl \nNs 0\nKd 0.63 0.065 "
    "0.05\nKe 1 2 3\nd 1\n");
  std::string obj = twoMaterialObj("scene.mtl");
  replaceOnce(obj, "usemtl red\n", "usemtl \n");
  writeFile(folder / "scene.obj", obj);
  const ReadResult result = readScene(folder / "scene.obj");
  ASSERT_TRUE(result.succeeded) << result.errors();
  expectRgbNear(tuple3(result.output, "Reflectance", 0), 0.725, 0.71, 0.68, 1e-12);
  expectRgbNear(tuple3(result.output, "Reflectance", 3), 0.63, 0.065, 0.05, 1e-12);
  expectRgbNear(tuple3(result.output, "Emission", 3), Pi, 2 * Pi, 3 * Pi, 1e-12);
  EXPECT_EQ(materialNames(result.output), (std::vector<std::string>{ "white", "none" }));
  EXPECT_NE(result.warnings().find("line 13: 'usemtl' without a material name; the faces after "
                                   "it (and after any other such line) have the material "
                                   "library's unnamed material"),
    std::string::npos)
    << result.warnings();

  // Faces before any 'usemtl' keep the default grey, and so do those of the bare 'usemtl'
  // that shares their material 'none'.
  writeFile(folder / "early.obj", "v 9 9 9\nv 9 8 9\nv 8 9 9\nf 1 2 3\n" + obj);
  const ReadResult early = readScene(folder / "early.obj");
  ASSERT_TRUE(early.succeeded) << early.errors();
  ASSERT_EQ(early.output->GetNumberOfCells(), 5);
  expectRgbNear(tuple3(early.output, "Reflectance", 4), 0.5, 0.5, 0.5, 0);
  EXPECT_NE(early.warnings().find("have the default material, grey 0.5"), std::string::npos)
    << early.warnings();
}

TEST(SceneReader, MaterialNamesWithControlCharactersSurviveAnXmlRoundTrip)
{
  // VTK's XML files end each string value with a NUL byte: a name holding one came back as
  // two values, and the XML reader then wrote past the array's end.
  const TestFolder scratch("control-characters");
  const fs::path& folder = scratch.path;
  writeFile(folder / "scene.obj",
    std::string("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl a\0b\tc\nf 1 2 3\n"
                "usemtl d\nf 1 3 4\n",
      70));
  const ReadResult result = readScene(folder / "scene.obj");
  ASSERT_TRUE(result.succeeded) << result.errors();
  EXPECT_EQ(materialNames(result.output), (std::vector<std::string>{ "a?b?c", "d" }));
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetInputData(result.output);
  writer->WriteToOutputStringOn();
  ASSERT_EQ(writer->Write(), 1);
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->ReadFromInputStringOn();
  reader->SetInputString(writer->GetOutputString());
  reader->Update();
  EXPECT_EQ(materialNames(reader->GetOutput()), materialNames(result.output));
}

// --- The same scene in every format -----------------------------------------------------------

TEST(SceneReader, ObjGltfGlbAndPlyGiveTheSameReflectances)
{
  const TestFolder scratch("formats");
  const fs::path& folder = scratch.path;
  writeFile(
    folder / "scene.mtl", "newmtl white\nKd 0.725 0.71 0.68\nnewmtl red\nKd 0.63 0.065 0.05\n");
  writeFile(folder / "scene.obj", twoMaterialObj("scene.mtl"));
  writeFile(folder / "scene.gltf", gltfJson(dataUri(gltfBuffer())));
  writeFile(folder / "scene.glb", glbFile(gltfJson(""), gltfBuffer()));
  writeFile(folder / "scene data.bin", gltfBuffer());
  writeFile(folder / "external.gltf", gltfJson("scene%20data.bin"));

  // PLY, ASCII with float face colours (exact) and binary with 8-bit vertex colours.
  std::string ascii =
    "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
    "property float z\nelement face 4\nproperty list uchar int vertex_indices\n"
    "property float red\nproperty float green\nproperty float blue\nend_header\n";
  for (const auto& corner : Corners)
  {
    ascii += std::to_string(corner[0]) + " " + std::to_string(corner[1]) + " " +
      std::to_string(corner[2]) + "\n";
  }
  for (int f = 0; f < 4; ++f)
  {
    const double* kd = f < 2 ? White : Red;
    ascii += "3 " + std::to_string(Triangles[f][0]) + " " + std::to_string(Triangles[f][1]) + " " +
      std::to_string(Triangles[f][2]) + " " + std::to_string(kd[0]) + " " + std::to_string(kd[1]) +
      " " + std::to_string(kd[2]) + "\n";
  }
  writeFile(folder / "faces.ply", ascii);
  std::string binary = "ply\nformat binary_little_endian 1.0\ncomment per-vertex colours\n"
                       "element vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
                       "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                       "element face 4\nproperty list uchar uint vertex_indices\nend_header\n";
  for (int v = 0; v < 8; ++v)
  {
    binary.append(reinterpret_cast<const char*>(Corners[v]), 12);
    const double* kd = v < 4 ? White : Red;
    for (int c = 0; c < 3; ++c)
    {
      binary += static_cast<char>(static_cast<int>(std::lround(kd[c] * 255)));
    }
  }
  for (const auto& triangle : Triangles)
  {
    binary += static_cast<char>(3);
    for (std::uint16_t index : triangle)
    {
      const std::uint32_t wide = index;
      binary.append(reinterpret_cast<const char*>(&wide), 4);
    }
  }
  writeFile(folder / "vertices.ply", binary);

  const ReadResult obj = readScene(folder / "scene.obj");
  ASSERT_TRUE(obj.succeeded) << obj.errors();
  expectTwoMaterialScene(obj.output, 1e-6);
  for (const char* name :
    { "scene.gltf", "scene.glb", "external.gltf", "faces.ply", "vertices.ply" })
  {
    SCOPED_TRACE(name);
    const ReadResult other = readScene(folder / name);
    ASSERT_TRUE(other.succeeded) << other.errors();
    EXPECT_EQ(other.errors(), "");
    EXPECT_EQ(other.warnings(), "");
    // 8-bit colours are the reflectance to within half a step.
    expectTwoMaterialScene(other.output, std::string(name) == "vertices.ply" ? 0.5 / 255 : 1e-6);
    for (vtkIdType cell = 0; cell < 4; ++cell)
    {
      expectRgbNear(tuple3(other.output, "Reflectance", cell),
        tuple3(obj.output, "Reflectance", cell)[0], tuple3(obj.output, "Reflectance", cell)[1],
        tuple3(obj.output, "Reflectance", cell)[2], 0.5 / 255);
    }
  }
  const ReadResult gltf = readScene(folder / "scene.gltf");
  EXPECT_EQ(materialNames(gltf.output), (std::vector<std::string>{ "white", "red" }));
  EXPECT_EQ(materialId(gltf.output, 0), 0);
  EXPECT_EQ(materialId(gltf.output, 3), 1);
  EXPECT_EQ(stringField(gltf.output, "SceneFormat"), "glTF");
  EXPECT_EQ(stringField(readScene(folder / "faces.ply").output, "SceneFormat"), "PLY");
  EXPECT_EQ(
    materialNames(readScene(folder / "faces.ply").output), (std::vector<std::string>{ "faces" }));
}

// --- PLY triangle strips (Stanford's igea.ply, the trimesh2 tools) ---------------------------
namespace
{
// Six vertices along a 2 x 1 strip in z = 0; the strip 0 1 2 3 4 5 makes the triangles
// (0 1 2), (2 1 3), (2 3 4), (4 3 5), every other one turned, all facing -z.
const float StripCorners[6][3] = { { 0, 0, 0 }, { 0, 1, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 2, 0, 0 },
  { 2, 1, 0 } };
const std::vector<std::array<vtkIdType, 3>> StripTriangles = { { { 0, 1, 2 } }, { { 2, 1, 3 } },
  { { 2, 3, 4 } }, { { 4, 3, 5 } } };

std::string stripHeader(const std::string& format, const std::string& vertexExtra,
  const std::string& between, std::size_t strips = 1)
{
  return "ply\nformat " + format +
    " 1.0\ncomment strips as trimesh2 writes them\nelement vertex 6\nproperty float x\n"
    "property float y\nproperty float z\n" +
    vertexExtra + between + "element tristrips " + std::to_string(strips) +
    "\nproperty list int int vertex_indices\nend_header\n";
}

std::string asciiStripFile(const std::vector<int>& indices)
{
  std::string text = stripHeader("ascii", "", "");
  for (const auto& corner : StripCorners)
  {
    text += std::to_string(corner[0]) + " " + std::to_string(corner[1]) + " " +
      std::to_string(corner[2]) + "\n";
  }
  text += std::to_string(indices.size());
  for (int index : indices)
  {
    text += " " + std::to_string(index);
  }
  return text + "\n";
}

void appendBigEndian(std::string& out, std::uint32_t bits)
{
  for (int shift = 24; shift >= 0; shift -= 8)
  {
    out += static_cast<char>((bits >> shift) & 0xff);
  }
}

std::vector<std::array<vtkIdType, 3>> triangles(vtkPolyData* mesh)
{
  std::vector<std::array<vtkIdType, 3>> result;
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < mesh->GetNumberOfCells(); ++c)
  {
    mesh->GetCellPoints(c, ids);
    if (ids->GetNumberOfIds() == 3)
    {
      result.push_back({ { ids->GetId(0), ids->GetId(1), ids->GetId(2) } });
    }
  }
  return result;
}
} // namespace

TEST(SceneReader, PlyTriangleStripsBecomeTrianglesFacingOneWay)
{
  const TestFolder scratch("ply-strips");
  const fs::path& folder = scratch.path;
  // One strip; two strips split by -1; one strip joined by repeated indices, whose four
  // triangles without area are dropped but still turn the ones after them.
  writeFile(folder / "one.ply", asciiStripFile({ 0, 1, 2, 3, 4, 5 }));
  writeFile(folder / "restart.ply", asciiStripFile({ 0, 1, 2, 3, -1, 2, 3, 4, 5, -1 }));
  writeFile(folder / "joined.ply", asciiStripFile({ 0, 1, 2, 3, 3, 2, 2, 3, 4, 5 }));
  // Big-endian binary with vertex colours and an empty face element before the strips, two
  // strip rows (-1 ending the first) and a strip of two vertices, which makes nothing.
  std::string binary = stripHeader("binary_big_endian",
    "property uchar red\nproperty uchar green\nproperty uchar blue\n",
    "element face 0\nproperty list uchar int vertex_indices\n", 3);
  for (int v = 0; v < 6; ++v)
  {
    for (float coordinate : StripCorners[v])
    {
      std::uint32_t bits;
      std::memcpy(&bits, &coordinate, 4);
      appendBigEndian(binary, bits);
    }
    binary += static_cast<char>(v * 51); // red 0, 51, ..., 255 (0.2 steps); green, blue 0
    binary += '\0';
    binary += '\0';
  }
  for (const std::vector<int>& strip : { std::vector<int>{ 0, 1, 2, 3, -1 },
         std::vector<int>{ 2, 3, 4, 5 }, std::vector<int>{ 4, 5 } })
  {
    appendBigEndian(binary, static_cast<std::uint32_t>(strip.size()));
    for (int index : strip)
    {
      appendBigEndian(binary, static_cast<std::uint32_t>(index));
    }
  }
  writeFile(folder / "binary.ply", binary);

  for (const char* name : { "one.ply", "restart.ply", "joined.ply", "binary.ply" })
  {
    SCOPED_TRACE(name);
    const ReadResult result = readScene(folder / name);
    ASSERT_TRUE(result.succeeded) << result.errors();
    EXPECT_EQ(result.errors(), "");
    EXPECT_EQ(stringField(result.output, "SceneFormat"), "PLY");
    EXPECT_EQ(triangles(result.output), StripTriangles);
    for (vtkIdType c = 0; c < result.output->GetNumberOfCells(); ++c)
    {
      double a[3], b[3], d[3];
      const auto& t = StripTriangles[static_cast<std::size_t>(c)];
      result.output->GetPoint(t[0], a);
      result.output->GetPoint(t[1], b);
      result.output->GetPoint(t[2], d);
      const double normalZ = (b[0] - a[0]) * (d[1] - a[1]) - (b[1] - a[1]) * (d[0] - a[0]);
      EXPECT_NEAR(normalZ, -1.0, 1e-12) << "triangle " << c;
    }
    if (std::string(name) == "binary.ply")
    {
      EXPECT_EQ(result.warnings(), "");
      // A triangle's reflectance is the mean of its vertices' colours: (2 1 3) 0.4.
      expectRgbNear(tuple3(result.output, "Reflectance", 1), 0.4, 0, 0, 1e-6);
      expectRgbNear(tuple3(result.output, "Reflectance", 3), 0.8, 0, 0, 1e-6);
    }
    else
    {
      EXPECT_NE(result.warnings().find("no red/green/blue colours"), std::string::npos)
        << result.warnings();
    }
  }
}

TEST(SceneReader, PlyHeaderLineWithoutAKeywordIsReadAsACommentWithAWarning)
{
  // Blender 2.4x wrote its credit line without 'comment' (assimp's test model Wuson.ply, and
  // the PLY files of that Blender in the wild); VTK's reader skips it. It was refused.
  const TestFolder scratch("ply-blender24");
  const fs::path& folder = scratch.path;
  writeFile(folder / "blender24.ply",
    "ply\nformat ascii 1.0\nCreated by Blender3D 247 - www.blender.org, source file: \n"
    "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    "property uchar red\nproperty uchar green\nproperty uchar blue\n"
    "element face 1\nproperty list uchar uint vertex_indices\nend_header\n"
    "0 0 0 51 102 153\n2 0 0 51 102 153\n2 3 0 51 102 153\n0 3 0 51 102 153\n4 0 1 2 3\n");
  const ReadResult result = readScene(folder / "blender24.ply");
  ASSERT_TRUE(result.succeeded) << result.errors();
  ASSERT_EQ(result.output->GetNumberOfCells(), 1);
  EXPECT_EQ(result.output->GetCell(0)->GetNumberOfPoints(), 4);
  double bounds[6];
  result.output->GetBounds(bounds);
  EXPECT_DOUBLE_EQ(bounds[1], 2);
  EXPECT_DOUBLE_EQ(bounds[3], 3);
  expectRgbNear(tuple3(result.output, "Reflectance", 0), 0.2, 0.4, 0.6, 1e-12);
  EXPECT_NE(result.warnings().find("blender24.ply' has 1 header line(s) of no PLY keyword, read "
                                   "as comments: line 3 'Created by Blender3D 247"),
    std::string::npos)
    << result.warnings();
}

TEST(SceneReader, GltfNodeTransformsAndEmission)
{
  const TestFolder scratch("gltf-emission");
  const fs::path& folder = scratch.path;
  // The red material emits (1, 0.5, 0.25) x strength 4 as radiance, like Ke 4 2 1.
  std::string json = gltfJson(dataUri(gltfBuffer()), "", "[1, 2, 3]");
  const std::string red =
    R"({"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [0.63, 0.065, 0.05, 1]}})";
  replaceOnce(json, red,
    R"({"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [0.63, 0.065, 0.05, 1]},
        "emissiveFactor": [1, 0.5, 0.25],
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}}})");
  replaceOnce(json, R"("scene": 0,)",
    R"("scene": 0, "extensionsUsed": ["KHR_materials_emissive_strength"],)");
  writeFile(folder / "lamp.gltf", json);
  const ReadResult result = readScene(folder / "lamp.gltf");
  ASSERT_TRUE(result.succeeded) << result.errors();
  EXPECT_EQ(result.warnings(), "");
  vtkPolyData* mesh = result.output;
  ASSERT_EQ(mesh->GetNumberOfCells(), 4);
  // The two primitives share one POSITION accessor of 8 vertices, 4 used by each: each keeps
  // the vertices it uses, not a copy of the whole accessor (8 points, not 16).
  EXPECT_EQ(mesh->GetNumberOfPoints(), 8);
  expectRgbNear(tuple3(mesh, "Emission", 0), 0, 0, 0, 0);
  expectRgbNear(tuple3(mesh, "Emission", 2), 4 * Pi, 2 * Pi, 1 * Pi, 1e-6);
  double bounds[6];
  mesh->GetBounds(bounds);
  EXPECT_NEAR(bounds[0], 1, 1e-6);
  EXPECT_NEAR(bounds[1], 2, 1e-6);
  EXPECT_NEAR(bounds[2], 2, 1e-6);
  EXPECT_NEAR(bounds[5], 4, 1e-6);
}

/// A PNG of 2 x 2 texels, each (r, g, b) of `texels`.
std::string pngImage(const std::array<std::array<int, 3>, 4>& texels)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(2, 2, 1);
  image->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* scalars = vtkUnsignedCharArray::SafeDownCast(image->GetPointData()->GetScalars());
  for (vtkIdType t = 0; t < 4; ++t)
  {
    for (int c = 0; c < 3; ++c)
    {
      scalars->SetTypedComponent(t, c,
        static_cast<unsigned char>(
          texels[static_cast<std::size_t>(t)][static_cast<std::size_t>(c)]));
    }
  }
  auto writer = vtkSmartPointer<vtkPNGWriter>::New();
  writer->SetInputData(image);
  writer->WriteToMemoryOn();
  writer->Write();
  vtkUnsignedCharArray* bytes = writer->GetResult();
  return std::string(reinterpret_cast<const char*>(bytes->GetPointer(0)),
    static_cast<std::size_t>(bytes->GetNumberOfValues()));
}

double srgbToLinear(double value)
{
  return value <= 0.04045 ? value / 12.92 : std::pow((value + 0.055) / 1.055, 2.4);
}

TEST(SceneReader, GltfBaseColourTextureIsAveragedInLinearColour)
{
  const TestFolder scratch("gltf-texture");
  const fs::path& folder = scratch.path;
  // Half the texels white, half black in red and blue; green 128 everywhere (sRGB, so 0.2159
  // in linear light). The factor multiplies the mean.
  const std::string png =
    pngImage({ { { 255, 128, 0 }, { 0, 128, 255 }, { 255, 128, 0 }, { 0, 128, 255 } } });
  writeFile(folder / "wood.png", png);
  std::string json = gltfJson(dataUri(gltfBuffer()),
    R"(,
  "textures": [{"source": 0}, {"source": 1}],
  "images": [{"uri": "data:image/png;base64,)" +
      base64(png) + R"("}, {"uri": "wood.png"}])");
  const std::string white =
    R"({"name": "white", "pbrMetallicRoughness": {"baseColorFactor": [0.725, 0.71, 0.68, 1]}})";
  replaceOnce(json, white,
    R"({"name": "white", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 1, 0.6, 1], "baseColorTexture": {"index": 0}}})");
  const std::string red =
    R"({"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [0.63, 0.065, 0.05, 1]}})";
  replaceOnce(
    json, red, R"({"name": "red", "pbrMetallicRoughness": {"baseColorTexture": {"index": 1}}})");
  writeFile(folder / "textured.gltf", json);
  const ReadResult result = readScene(folder / "textured.gltf");
  ASSERT_TRUE(result.succeeded) << result.errors();
  EXPECT_EQ(result.warnings(), "");
  const double green = srgbToLinear(128 / 255.0);
  expectRgbNear(tuple3(result.output, "Reflectance", 0), 0.8 * 0.5, green, 0.6 * 0.5, 1e-9,
    "data: URI texture");
  expectRgbNear(
    tuple3(result.output, "Reflectance", 2), 0.5, green, 0.5, 1e-9, "texture file beside the glTF");

  // A damaged image (a byte of its pixel data changed: the chunk's CRC no longer matches) is
  // a warning naming the material, and its factor alone gives the reflectance.
  std::string damaged = png;
  damaged[damaged.size() - 20] = static_cast<char>(damaged[damaged.size() - 20] ^ 0x5a);
  writeFile(folder / "wood.png", damaged);
  const ReadResult broken = readScene(folder / "textured.gltf");
  ASSERT_TRUE(broken.succeeded) << broken.errors();
  EXPECT_NE(broken.warnings().find("'red'"), std::string::npos) << broken.warnings();
  EXPECT_NE(broken.warnings().find("could not be decoded"), std::string::npos) << broken.warnings();
  expectRgbNear(tuple3(broken.output, "Reflectance", 2), 0.99, 0.99, 0.99, 0, "damaged texture");
}

TEST(SceneReader, GltfTexturesOfWebpOrKtx2AreWarnedOfAndTheFileIsRead)
{
  // EXT_texture_webp (and KHR_texture_basisu) put an image of their format in a bufferView,
  // as gltf-transform and the glTF-Sample-Assets' WEBP and KTX2 variants write them: such a
  // texture cannot be decoded here, which is a warning naming the material (the factor alone
  // is used), not a reason to refuse the scene. Both were refused: the required extension,
  // and the image's mimeType image/webp.
  const TestFolder scratch("gltf-webp");
  const fs::path& folder = scratch.path;
  std::string buffer = gltfBuffer();
  const std::string webp = std::string("RIFF\x1a\0\0\0WEBPVP8L", 16) + std::string(14, '\0');
  buffer += webp;
  std::string json = gltfJson(dataUri(buffer),
    R"(,
  "textures": [{"extensions": {"EXT_texture_webp": {"source": 0}}}, {"source": 0}],
  "images": [{"bufferView": 2, "mimeType": "image/webp"}])");
  replaceOnce(json, R"("byteLength": 120})", R"("byteLength": 150})");
  replaceOnce(json, R"({"buffer": 0, "byteOffset": 96, "byteLength": 24}])",
    R"({"buffer": 0, "byteOffset": 96, "byteLength": 24},
    {"buffer": 0, "byteOffset": 120, "byteLength": 30}])");
  replaceOnce(json, R"("baseColorFactor": [0.725, 0.71, 0.68, 1]})",
    R"("baseColorFactor": [0.725, 0.71, 0.68, 1], "baseColorTexture": {"index": 0}})");
  replaceOnce(json, R"("baseColorFactor": [0.63, 0.065, 0.05, 1]})",
    R"("baseColorFactor": [0.63, 0.065, 0.05, 1], "baseColorTexture": {"index": 1}})");
  std::string required = json;
  replaceOnce(required, R"("scene": 0,)", R"("scene": 0,
  "extensionsUsed": ["EXT_texture_webp"], "extensionsRequired": ["EXT_texture_webp"],)");
  writeFile(folder / "used.gltf", json);
  writeFile(folder / "required.gltf", required);
  for (const char* name : { "used.gltf", "required.gltf" })
  {
    SCOPED_TRACE(name);
    const ReadResult result = readScene(folder / name);
    ASSERT_TRUE(result.succeeded) << result.errors();
    expectTwoMaterialScene(result.output, 1e-12);
    for (const char* material : { "'white'", "'red'" })
    {
      EXPECT_NE(
        result.warnings().find(std::string("the glTF material ") + material), std::string::npos)
        << result.warnings();
    }
    EXPECT_NE(result.warnings().find("neither PNG nor JPEG, so its factor alone is used"),
      std::string::npos)
      << result.warnings();
  }
  // An extension's image index is checked as the core one is.
  replaceOnce(required, R"({"source": 0}}})", R"({"source": 7}}})");
  writeFile(folder / "bad-index.gltf", required);
  const ReadResult bad = readScene(folder / "bad-index.gltf");
  EXPECT_FALSE(bad.succeeded);
  EXPECT_NE(
    bad.errors().find("textures[0].extensions.EXT_texture_webp.source = 7"), std::string::npos)
    << bad.errors();
}

/// An OBJ file with one unit quad per material of `materials`, in that order, reading `mtl`.
std::string quadPerMaterialObj(const std::string& mtl, const std::vector<std::string>& materials)
{
  std::string text = "mtllib " + mtl + "\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
  for (const auto& name : materials)
  {
    text += "usemtl " + name + "\nf 1 2 3 4\n";
  }
  return text;
}

TEST(SceneReader, ObjMapKdMultipliesKdByTheTextureMeanInLinearColour)
{
  const TestFolder scratch("obj-texture");
  const fs::path& folder = scratch.path;
  // The glTF test's texture: red and blue half white, half black; green 128 (sRGB) everywhere.
  writeFile(folder / "tex.png",
    pngImage({ { { 255, 128, 0 }, { 0, 128, 255 }, { 255, 128, 0 }, { 0, 128, 255 } } }));
  fs::create_directories(folder / "textures");
  writeFile(folder / "textures" / "wood grain.png",
    pngImage({ { { 200, 100, 50 }, { 200, 100, 50 }, { 200, 100, 50 }, { 200, 100, 50 } } }));
  // Options before the file name (each with its number of values), a name with a space, in a
  // subfolder written with a back slash as Windows exporters do; map_Ke scales Ke.
  writeFile(folder / "scene.mtl", R"(newmtl plain
Kd 0.8 0.8 0.8
map_Kd tex.png
newmtl optioned
Kd 1 0.5 1
map_Kd -s 1 1 1 -o 0 0 -bm 0.5 -clamp on -mm 0 1 -blendu off -texres 512 -imfchan l textures\wood grain.png
newmtl textureonly
map_Kd tex.png
newmtl glow
Kd 0.5
Ke 2 4 6
map_Ke tex.png
)");
  writeFile(folder / "scene.obj",
    quadPerMaterialObj("scene.mtl", { "plain", "optioned", "textureonly", "glow" }));
  const ReadResult result = readScene(folder / "scene.obj");
  ASSERT_TRUE(result.succeeded) << result.errors();
  EXPECT_EQ(result.warnings(), "");
  const double green = srgbToLinear(128 / 255.0);
  expectRgbNear(tuple3(result.output, "Reflectance", 0), 0.8 * 0.5, 0.8 * green, 0.8 * 0.5, 1e-6,
    "Kd 0.8 x texture");
  expectRgbNear(tuple3(result.output, "Reflectance", 1), srgbToLinear(200 / 255.0),
    0.5 * srgbToLinear(100 / 255.0), srgbToLinear(50 / 255.0), 1e-6,
    "options before the file name");
  expectRgbNear(
    tuple3(result.output, "Reflectance", 2), 0.5, green, 0.5, 1e-6, "map_Kd without Kd");
  expectRgbNear(tuple3(result.output, "Reflectance", 3), 0.5, 0.5, 0.5, 1e-6, "glow's Kd");
  // Emission is the exitance, pi x radiance.
  expectRgbNear(tuple3(result.output, "Emission", 3), 2 * 0.5 * Pi, 4 * green * Pi, 6 * 0.5 * Pi,
    1e-6, "Ke x map_Ke");
  expectRgbNear(tuple3(result.output, "Emission", 0), 0, 0, 0, 0, "no Ke");

  // Kd 1 1 1 with a white texture is still clamped, with the clamping's warning.
  writeFile(folder / "white.png",
    pngImage({ { { 255, 255, 255 }, { 255, 255, 255 }, { 255, 255, 255 }, { 255, 255, 255 } } }));
  writeFile(folder / "scene.mtl", "newmtl plain\nKd 1 1 1\nmap_Kd white.png\n");
  writeFile(folder / "scene.obj", quadPerMaterialObj("scene.mtl", { "plain" }));
  const ReadResult white = readScene(folder / "scene.obj");
  ASSERT_TRUE(white.succeeded) << white.errors();
  EXPECT_NE(white.warnings().find("clamped"), std::string::npos) << white.warnings();
  expectRgbNear(tuple3(white.output, "Reflectance", 0), 0.99, 0.99, 0.99, 0, "clamped");
}

TEST(SceneReader, ObjTextureThatCannotBeUsedIsAWarningAndKdAloneIsUsed)
{
  const TestFolder scratch("obj-bad-texture");
  const fs::path& folder = scratch.path;
  writeFile(folder / "notes.txt", "not an image, though named in map_Kd\n");
  std::string damaged =
    pngImage({ { { 255, 128, 0 }, { 0, 128, 255 }, { 255, 128, 0 }, { 0, 128, 255 } } });
  damaged[damaged.size() - 20] = static_cast<char>(damaged[damaged.size() - 20] ^ 0x5a);
  writeFile(folder / "damaged.png", damaged);
  fs::create_directories(folder / "folder.png");
  // Each refused quickly, without reading more than a signature: missing, not an image, a
  // folder, a device that never ends, a damaged PNG; and a map_Kd without a file name.
  const std::vector<std::pair<std::string, std::string>> cases = { { "missing", "absent.png" },
    { "text", "notes.txt" }, { "folder", "folder.png" }, { "device", "/dev/zero" },
    { "damaged", "damaged.png" } };
  std::string mtl, names;
  std::vector<std::string> materials;
  for (const auto& [name, file] : cases)
  {
    mtl += "newmtl " + name + "\nKd 0.3 0.4 0.5\nmap_Kd -s 2 2 " + file + "\n";
    materials.push_back(name);
  }
  mtl += "newmtl nofile\nKd 0.3 0.4 0.5\nmap_Kd\n";
  materials.push_back("nofile");
  writeFile(folder / "scene.mtl", mtl);
  writeFile(folder / "scene.obj", quadPerMaterialObj("scene.mtl", materials));
  const ReadResult result = readScene(folder / "scene.obj");
  ASSERT_TRUE(result.succeeded) << result.errors();
  const std::string warnings = result.warnings();
  for (std::size_t i = 0; i < cases.size(); ++i)
  {
    const auto& [name, file] = cases[i];
    const fs::path path = file[0] == '/' ? fs::path(file) : folder / file;
    const std::string expected = "material '" + name + "' of '" + (folder / "scene.obj").string() +
      "': its map_Kd texture '" + path.string() + "': ";
    EXPECT_NE(warnings.find(expected), std::string::npos) << expected << "\nin\n" << warnings;
    expectRgbNear(
      tuple3(result.output, "Reflectance", static_cast<vtkIdType>(i)), 0.3, 0.4, 0.5, 1e-12, name);
  }
  EXPECT_NE(warnings.find("does not exist, so Kd alone is used"), std::string::npos) << warnings;
  EXPECT_NE(
    warnings.find("its image is neither PNG nor JPEG, so Kd alone is used"), std::string::npos)
    << warnings;
  EXPECT_NE(warnings.find("its file is a folder"), std::string::npos) << warnings;
  EXPECT_NE(warnings.find("its file is not a regular file"), std::string::npos) << warnings;
  EXPECT_NE(warnings.find("its PNG image could not be decoded"), std::string::npos) << warnings;
  EXPECT_NE(warnings.find("'map_Kd' names no file"), std::string::npos) << warnings;
  expectRgbNear(tuple3(result.output, "Reflectance", static_cast<vtkIdType>(cases.size())), 0.3,
    0.4, 0.5, 1e-12, "nofile");
}

TEST(SceneReader, ObjJpegTextureIsAveragedAndAHugeOneRefused)
{
  const TestFolder scratch("obj-jpeg");
  const fs::path& folder = scratch.path;
  // One colour over 8 x 8 texels (a whole JPEG block), at the best quality: decoded within a
  // level or two of what was written.
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(8, 8, 1);
  image->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* scalars = vtkUnsignedCharArray::SafeDownCast(image->GetPointData()->GetScalars());
  const unsigned char colour[3] = { 200, 100, 50 };
  for (vtkIdType t = 0; t < 64; ++t)
  {
    for (int c = 0; c < 3; ++c)
    {
      scalars->SetTypedComponent(t, c, colour[c]);
    }
  }
  auto writer = vtkSmartPointer<vtkJPEGWriter>::New();
  writer->SetInputData(image);
  writer->SetQuality(100);
  writer->WriteToMemoryOn();
  writer->Write();
  vtkUnsignedCharArray* bytes = writer->GetResult();
  std::string jpeg(reinterpret_cast<const char*>(bytes->GetPointer(0)),
    static_cast<std::size_t>(bytes->GetNumberOfValues()));
  writeFile(folder / "tex.jpg", jpeg);
  // The same file whose frame header (SOFn: FF C0, C1 or C2 (VTK writes progressive JPEG),
  // length, precision, height, width) claims 65535 x 65535 texels: refused before the decoder
  // allocates them.
  std::size_t frame = std::string::npos;
  for (const char* marker : { "\xff\xc0", "\xff\xc1", "\xff\xc2" })
  {
    frame = std::min(frame, jpeg.find(marker, 2));
  }
  ASSERT_NE(frame, std::string::npos);
  for (std::size_t i = frame + 5; i < frame + 9; ++i)
  {
    jpeg[i] = '\xff';
  }
  writeFile(folder / "huge.jpg", jpeg);
  writeFile(folder / "scene.mtl",
    "newmtl jpeg\nKd 0.5\nmap_Kd tex.jpg\nnewmtl huge\nKd 0.5\nmap_Kd huge.jpg\n");
  writeFile(folder / "scene.obj", quadPerMaterialObj("scene.mtl", { "jpeg", "huge" }));
  const ReadResult result = readScene(folder / "scene.obj");
  ASSERT_TRUE(result.succeeded) << result.errors();
  expectRgbNear(tuple3(result.output, "Reflectance", 0), 0.5 * srgbToLinear(200 / 255.0),
    0.5 * srgbToLinear(100 / 255.0), 0.5 * srgbToLinear(50 / 255.0), 0.005, "JPEG");
  EXPECT_NE(result.warnings().find("'huge'"), std::string::npos) << result.warnings();
  EXPECT_NE(result.warnings().find("its JPEG image is larger than 64 Mpixels, so Kd alone is used"),
    std::string::npos)
    << result.warnings();
  expectRgbNear(tuple3(result.output, "Reflectance", 1), 0.5, 0.5, 0.5, 0, "huge JPEG");
}

TEST(SceneReader, GltfMaterialsWithoutPbrStripsAndFans)
{
  const TestFolder scratch("gltf-modes");
  const fs::path& folder = scratch.path;
  // VTK 9.2's vtkGLTFDocumentLoader aborts on a material without pbrMetallicRoughness; glTF's
  // default for it is white, which is clamped with a warning. Strips and fans make triangles.
  std::string json = gltfJson(dataUri(gltfBuffer()));
  const std::string white =
    R"({"name": "white", "pbrMetallicRoughness": {"baseColorFactor": [0.725, 0.71, 0.68, 1]}})";
  replaceOnce(json, white, R"({"name": "lamp", "emissiveFactor": [1, 1, 1]})");
  replaceOnce(
    json, R"("indices": 1, "material": 0, "mode": 4)", R"("indices": 1, "material": 0, "mode": 5)");
  replaceOnce(
    json, R"("indices": 2, "material": 1, "mode": 4)", R"("indices": 2, "material": 1, "mode": 6)");
  writeFile(folder / "modes.gltf", json);
  const ReadResult result = readScene(folder / "modes.gltf");
  ASSERT_TRUE(result.succeeded) << result.errors();
  // Indices 0 1 2 0 2 3: a strip gives 4 triangles, a fan (4 5 6 4 6 7) 4 too.
  EXPECT_EQ(result.output->GetNumberOfCells(), 8);
  EXPECT_NE(result.warnings().find("'lamp'"), std::string::npos) << result.warnings();
  expectRgbNear(tuple3(result.output, "Reflectance", 0), 0.99, 0.99, 0.99, 0);
  expectRgbNear(tuple3(result.output, "Emission", 0), Pi, Pi, Pi, 1e-12);
  expectRgbNear(tuple3(result.output, "Reflectance", 7), 0.63, 0.065, 0.05, 1e-6);
}

/// The normal (not normalised) of `cell`'s first three points, in their order.
std::array<double, 3> windingNormal(vtkPolyData* mesh, vtkIdType cell)
{
  vtkIdType count = 0;
  const vtkIdType* ids = nullptr;
  mesh->GetCellPoints(cell, count, ids);
  double p[3][3];
  for (int i = 0; i < 3; ++i)
  {
    mesh->GetPoint(ids[i], p[i]);
  }
  const double a[3] = { p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2] };
  const double b[3] = { p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2] };
  return { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
}

TEST(SceneReader, GltfMirroredNodeKeepsItsFrontFaces)
{
  // A node whose transform mirrors (negative determinant) makes clockwise triangles the front
  // ones (glTF 2.0, 3.7.4): the floor mirrored in z faces down, the wall still faces +x. Read
  // in the file's order, a mirrored lamp would shine into itself.
  const TestFolder scratch("gltf-mirror");
  const fs::path& folder = scratch.path;
  std::string json = gltfJson(dataUri(gltfBuffer()));
  writeFile(folder / "plain.gltf", json);
  replaceOnce(json, R"({"mesh": 0})", R"({"mesh": 0, "scale": [1, 1, -1]})");
  writeFile(folder / "mirrored.gltf", json);
  const ReadResult plain = readScene(folder / "plain.gltf");
  const ReadResult mirrored = readScene(folder / "mirrored.gltf");
  ASSERT_TRUE(plain.succeeded) << plain.errors();
  ASSERT_TRUE(mirrored.succeeded) << mirrored.errors();
  expectRgbNear(windingNormal(plain.output, 0), 0, 0, 1, 1e-6, "plain floor");
  expectRgbNear(windingNormal(mirrored.output, 0), 0, 0, -1, 1e-6, "mirrored floor");
  expectRgbNear(windingNormal(plain.output, 2), 1, 0, 0, 1e-6, "plain wall");
  expectRgbNear(windingNormal(mirrored.output, 2), 1, 0, 0, 1e-6, "mirrored wall");
  double bounds[6];
  mirrored.output->GetBounds(bounds);
  EXPECT_NEAR(bounds[4], -1, 1e-6);
  EXPECT_NEAR(bounds[5], 0, 1e-6);
}

/// The two-material scene with its positions given sparsely over zeros (an accessor without
/// a bufferView), a morph target that moves every vertex by (0, 0, 1) at the mesh's default
/// weight `weight`, and one punctual light: the buffer of gltfBuffer(), then 8 uint8 sparse
/// indices, then the target's 8 float displacements.
std::pair<std::string, std::string> sparseMorphedGltf(const std::string& weight)
{
  std::string buffer = gltfBuffer();
  for (char i = 0; i < 8; ++i)
  {
    buffer += i;
  }
  const float up[3] = { 0, 0, 1 };
  for (int v = 0; v < 8; ++v)
  {
    buffer.append(reinterpret_cast<const char*>(up), sizeof(up));
  }
  std::string json = gltfJson(dataUri(buffer));
  replaceOnce(json, R"("byteLength": 120})", R"("byteLength": 224})");
  replaceOnce(json, R"({"buffer": 0, "byteOffset": 96, "byteLength": 24}])",
    R"({"buffer": 0, "byteOffset": 96, "byteLength": 24},
    {"buffer": 0, "byteOffset": 120, "byteLength": 8},
    {"buffer": 0, "byteOffset": 128, "byteLength": 96}])");
  replaceOnce(json, R"({"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",)",
    R"({"componentType": 5126, "count": 8, "type": "VEC3",
     "sparse": {"count": 8, "indices": {"bufferView": 2, "componentType": 5121},
                "values": {"bufferView": 0}},)");
  replaceOnce(json, R"("type": "SCALAR"}])", R"("type": "SCALAR"},
    {"bufferView": 3, "componentType": 5126, "count": 8, "type": "VEC3"}])");
  replaceOnce(json, R"("indices": 1, "material": 0, "mode": 4})",
    R"("indices": 1, "material": 0, "mode": 4, "targets": [{"POSITION": 3}]})");
  replaceOnce(json, R"("indices": 2, "material": 1, "mode": 4}])",
    R"("indices": 2, "material": 1, "mode": 4, "targets": [{"POSITION": 3}]}], "weights": )" +
      weight);
  replaceOnce(json, R"("scene": 0,)", R"("scene": 0,
  "extensionsRequired": ["KHR_lights_punctual"], "extensionsUsed": ["KHR_lights_punctual"],
  "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point"}]}},)");
  return { json, buffer };
}

TEST(SceneReader, GltfSparseAccessorsMorphTargetsAndPunctualLights)
{
  const TestFolder scratch("gltf-sparse");
  const fs::path& folder = scratch.path;
  writeFile(folder / "morphed.gltf", sparseMorphedGltf("[0.5]").first);
  const ReadResult result = readScene(folder / "morphed.gltf");
  ASSERT_TRUE(result.succeeded) << result.errors();
  expectTwoMaterialScene(result.output, 1e-6);
  double bounds[6];
  result.output->GetBounds(bounds);
  // The sparse positions are the scene's; the target moves them up by half its (0, 0, 1).
  EXPECT_NEAR(bounds[1], 1, 1e-6);
  EXPECT_NEAR(bounds[3], 1, 1e-6);
  EXPECT_NEAR(bounds[4], 0.5, 1e-6);
  EXPECT_NEAR(bounds[5], 1.5, 1e-6);
  EXPECT_NE(result.warnings().find("a punctual light (KHR_lights_punctual): it is not read"),
    std::string::npos)
    << result.warnings();

  EXPECT_EQ(result.warnings().find("let light through"), std::string::npos) << result.warnings();

  // A cut-out material is read as opaque, with a warning naming it.
  std::string cutOut = sparseMorphedGltf("[0.5]").first;
  replaceOnce(cutOut, R"({"name": "red",)", R"({"name": "red", "alphaMode": "MASK",)");
  writeFile(folder / "cutout.gltf", cutOut);
  const ReadResult cut = readScene(folder / "cutout.gltf");
  ASSERT_TRUE(cut.succeeded) << cut.errors();
  EXPECT_NE(cut.warnings().find("1 material(s) that let light through (alphaMode MASK or BLEND, "
                                "or KHR_materials_transmission): 'red'"),
    std::string::npos)
    << cut.warnings();

  // Weights that do not match the targets, and a sparse index past the accessor's end.
  writeFile(folder / "weights.gltf", sparseMorphedGltf("[0.5, 1]").first);
  const ReadResult weights = readScene(folder / "weights.gltf");
  EXPECT_FALSE(weights.succeeded);
  EXPECT_NE(
    weights.errors().find("has 1 morph targets but its (or its node's) weights"), std::string::npos)
    << weights.errors();
  auto [json, buffer] = sparseMorphedGltf("[0]");
  buffer[127] = 8;
  replaceOnce(json,
    json.substr(json.find("data:"), json.find('"', json.find("data:")) - json.find("data:")),
    dataUri(buffer));
  writeFile(folder / "index.gltf", json);
  const ReadResult index = readScene(folder / "index.gltf");
  EXPECT_FALSE(index.succeeded);
  EXPECT_NE(index.errors().find("accessors[0].sparse names element 8 but the accessor has 8"),
    std::string::npos)
    << index.errors();
}

TEST(SceneReader, GltfSpecularGlossinessDiffuseIsTheReflectance)
{
  // KHR_materials_pbrSpecularGlossiness, as Sketchfab's and older exporters' files describe
  // materials: the diffuse factor (times its texture) is the reflectance, before any
  // metal-rough fallback. Without a pbrMetallicRoughness the material read as white (clamped
  // to 0.99 with a warning), and with one its fallback colour was read.
  const TestFolder scratch("gltf-specgloss");
  const fs::path& folder = scratch.path;
  std::string json = gltfJson(dataUri(gltfBuffer()));
  replaceOnce(json,
    R"({"name": "white", "pbrMetallicRoughness": {"baseColorFactor": [0.725, 0.71, 0.68, 1]}})",
    R"({"name": "white", "extensions": {"KHR_materials_pbrSpecularGlossiness":
      {"diffuseFactor": [0.725, 0.71, 0.68, 1], "specularFactor": [0.2, 0.2, 0.2]}}})");
  replaceOnce(json,
    R"({"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [0.63, 0.065, 0.05, 1]}})",
    R"({"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.1, 0.1, 1]},
      "extensions": {"KHR_materials_pbrSpecularGlossiness":
      {"diffuseFactor": [0.63, 0.065, 0.05, 1]}}})");
  replaceOnce(json, R"("scene": 0,)", R"("scene": 0,
  "extensionsUsed": ["KHR_materials_pbrSpecularGlossiness"],
  "extensionsRequired": ["KHR_materials_pbrSpecularGlossiness"],)");
  writeFile(folder / "specgloss.gltf", json);
  const ReadResult result = readScene(folder / "specgloss.gltf");
  ASSERT_TRUE(result.succeeded) << result.errors();
  expectTwoMaterialScene(result.output, 1e-12);
  EXPECT_EQ(result.warnings(), "");

  // Its diffuse texture's index is checked as a base colour texture's is.
  replaceOnce(json, R"("specularFactor": [0.2, 0.2, 0.2])",
    R"("specularFactor": [0.2, 0.2, 0.2], "diffuseTexture": {"index": 3})");
  writeFile(folder / "bad-texture.gltf", json);
  const ReadResult bad = readScene(folder / "bad-texture.gltf");
  EXPECT_FALSE(bad.succeeded);
  EXPECT_NE(
    bad.errors().find("materials[0].extensions.KHR_materials_pbrSpecularGlossiness.diffuseTexture"
                      ".index = 3 but the file has 0 textures"),
    std::string::npos)
    << bad.errors();
}

TEST(SceneReader, GltfGpuInstancesAreEachDrawn)
{
  // EXT_mesh_gpu_instancing (Blender's "GPU instances", gltfpack -mi, three.js' exporter): a
  // node draws its mesh once per instance, each moved by its own translation, rotation and
  // scale in the node's frame, a mirroring one keeping its front faces. Only the node's own
  // transform was read: one copy of a forest of trees, and a file that required the
  // extension was refused.
  const TestFolder scratch("gltf-instancing");
  const fs::path& folder = scratch.path;
  std::string buffer = gltfBuffer();
  const float instances[4][3] = { { 0, 0, 0 }, { 5, 0, 0 }, { 1, 1, 1 }, { 1, 1, -1 } };
  buffer.append(reinterpret_cast<const char*>(instances), sizeof(instances));
  std::string json = gltfJson(dataUri(buffer));
  replaceOnce(json, R"("byteLength": 120})", R"("byteLength": 168})");
  replaceOnce(json, R"({"buffer": 0, "byteOffset": 96, "byteLength": 24}])",
    R"({"buffer": 0, "byteOffset": 96, "byteLength": 24},
    {"buffer": 0, "byteOffset": 120, "byteLength": 48}])");
  replaceOnce(json, R"("count": 6, "type": "SCALAR"}])", R"("count": 6, "type": "SCALAR"},
    {"bufferView": 2, "componentType": 5126, "count": 2, "type": "VEC3"},
    {"bufferView": 2, "byteOffset": 24, "componentType": 5126, "count": 2, "type": "VEC3"}])");
  replaceOnce(json, R"({"mesh": 0})", R"({"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing":
    {"attributes": {"TRANSLATION": 3, "SCALE": 4}}}})");
  replaceOnce(json, R"("scene": 0,)", R"("scene": 0,
  "extensionsUsed": ["EXT_mesh_gpu_instancing"], "extensionsRequired": ["EXT_mesh_gpu_instancing"],)");
  writeFile(folder / "instanced.gltf", json);
  const ReadResult result = readScene(folder / "instanced.gltf");
  ASSERT_TRUE(result.succeeded) << result.errors();
  ASSERT_EQ(result.output->GetNumberOfCells(), 8);
  double bounds[6];
  result.output->GetBounds(bounds);
  const double expected[6] = { 0, 6, 0, 1, -1, 1 };
  for (int i = 0; i < 6; ++i)
  {
    EXPECT_NEAR(bounds[i], expected[i], 1e-9) << i;
  }
  expectRgbNear(windingNormal(result.output, 0), 0, 0, 1, 1e-6, "first floor");
  expectRgbNear(windingNormal(result.output, 4), 0, 0, -1, 1e-6, "mirrored floor");
  expectRgbNear(windingNormal(result.output, 6), 1, 0, 0, 1e-6, "mirrored wall");
  expectRgbNear(tuple3(result.output, "Reflectance", 6), Red[0], Red[1], Red[2], 1e-12);

  // Attributes of different counts are refused, naming the node.
  replaceOnce(json, R"("byteOffset": 24, "componentType": 5126, "count": 2)",
    R"("byteOffset": 24, "componentType": 5126, "count": 1)");
  writeFile(folder / "uneven.gltf", json);
  const ReadResult uneven = readScene(folder / "uneven.gltf");
  EXPECT_FALSE(uneven.succeeded);
  EXPECT_NE(uneven.errors().find("nodes[1].extensions.EXT_mesh_gpu_instancing.attributes.SCALE"),
    std::string::npos)
    << uneven.errors();
}

TEST(SceneReader, GltfQuantizedPositionsAreRead)
{
  // KHR_mesh_quantization, which gltfpack writes by default: positions as 16-bit integers
  // (padded to a stride of 8 bytes) under a node that scales them back, or as normalized
  // 8-bit integers. The two-material scene reads as from floats; it was refused.
  const TestFolder scratch("gltf-quantized");
  const fs::path& folder = scratch.path;
  auto quantized = [&](const std::string& componentType, bool normalized, int unit,
                     const std::string& scale, std::size_t componentBytes)
  {
    std::string buffer;
    for (const auto& corner : Corners)
    {
      for (int c = 0; c < 4; ++c)
      {
        const int value = c < 3 ? static_cast<int>(corner[c]) * unit : 0;
        for (std::size_t b = 0; b < componentBytes; ++b)
        {
          buffer += static_cast<char>((value >> (8 * b)) & 0xff);
        }
      }
    }
    const std::size_t positionBytes = buffer.size();
    buffer.append(
      reinterpret_cast<const char*>(Triangles), sizeof(Triangles)); // 24 bytes of indices
    std::string json = gltfJson(dataUri(buffer), "", "[0, 0, 0]");
    replaceOnce(
      json, R"("byteLength": 120})", R"("byteLength": )" + std::to_string(buffer.size()) + "}");
    replaceOnce(json, R"({"buffer": 0, "byteOffset": 0, "byteLength": 96},
    {"buffer": 0, "byteOffset": 96, "byteLength": 24}])",
      R"({"buffer": 0, "byteOffset": 0, "byteLength": )" + std::to_string(positionBytes) +
        R"(, "byteStride": )" + std::to_string(4 * componentBytes) + R"(},
    {"buffer": 0, "byteOffset": )" +
        std::to_string(positionBytes) + R"(, "byteLength": 24}])");
    replaceOnce(json, R"("componentType": 5126, "count": 8, "type": "VEC3",)",
      R"("componentType": )" + componentType + (normalized ? R"(, "normalized": true)" : "") +
        R"(, "count": 8, "type": "VEC3",)");
    replaceOnce(json, R"({"mesh": 0})", R"({"mesh": 0, "scale": )" + scale + "}");
    replaceOnce(json, R"("scene": 0,)", R"("scene": 0,
  "extensionsUsed": ["KHR_mesh_quantization"], "extensionsRequired": ["KHR_mesh_quantization"],)");
    return json;
  };
  writeFile(folder / "short.gltf", quantized("5123", false, 1000, "[0.001, 0.001, 0.001]", 2));
  writeFile(folder / "byte.gltf", quantized("5120", true, 127, "[1, 1, 1]", 1));
  for (const char* name : { "short.gltf", "byte.gltf" })
  {
    SCOPED_TRACE(name);
    const ReadResult result = readScene(folder / name);
    ASSERT_TRUE(result.succeeded) << result.errors();
    expectTwoMaterialScene(result.output, 1e-12);
    double bounds[6];
    result.output->GetBounds(bounds);
    for (int i = 0; i < 6; ++i)
    {
      EXPECT_NEAR(bounds[i], i % 2, 1e-9) << i;
    }
    EXPECT_NEAR(windingNormal(result.output, 0)[2], 1, 1e-9);
  }
  // Without the extension, integer positions are refused, naming it.
  std::string plain = quantized("5123", false, 1000, "[0.001, 0.001, 0.001]", 2);
  replaceOnce(plain,
    R"("extensionsUsed": ["KHR_mesh_quantization"], "extensionsRequired": ["KHR_mesh_quantization"],)",
    "");
  writeFile(folder / "plain.gltf", plain);
  const ReadResult refused = readScene(folder / "plain.gltf");
  EXPECT_FALSE(refused.succeeded);
  EXPECT_NE(
    refused.errors().find("integers need the extension KHR_mesh_quantization"), std::string::npos)
    << refused.errors();
}

namespace
{
/// The two-material glTF scene with a COLOR_0 accessor (3) of normalized 8-bit RGBA, `rgba`
/// at every vertex, that no primitive uses yet.
std::string gltfJsonWithVertexColour(const std::string& rgba)
{
  std::string buffer = gltfBuffer();
  for (int v = 0; v < 8; ++v)
  {
    buffer += rgba;
  }
  std::string json = gltfJson(dataUri(buffer));
  replaceOnce(json, R"("byteLength": 120)", R"("byteLength": 152)");
  replaceOnce(json, R"({"buffer": 0, "byteOffset": 96, "byteLength": 24}])",
    R"({"buffer": 0, "byteOffset": 96, "byteLength": 24},
    {"buffer": 0, "byteOffset": 120, "byteLength": 32}])");
  replaceOnce(json, R"("count": 6, "type": "SCALAR"}])",
    R"("count": 6, "type": "SCALAR"},
    {"bufferView": 2, "componentType": 5121, "normalized": true, "count": 8, "type": "VEC4"}])");
  return json;
}
} // namespace

TEST(SceneReader, GltfVertexColoursMultiplyTheBaseColourPerCell)
{
  const TestFolder scratch("gltf-colours");
  const fs::path& folder = scratch.path;
  // COLOR_0 (normalized 8-bit RGBA, linear) on the floor's primitive: every floor vertex
  // (255, 128, 0), so its cells reflect White x (1, 128/255, 0); the wall keeps its factor.
  std::string json = gltfJsonWithVertexColour(std::string("\xff\x80\x00\xff", 4));
  replaceOnce(
    json, R"("POSITION": 0}, "indices": 1)", R"("POSITION": 0, "COLOR_0": 3}, "indices": 1)");
  writeFile(folder / "colours.gltf", json);
  const ReadResult result = readScene(folder / "colours.gltf");
  ASSERT_TRUE(result.succeeded) << result.errors();
  expectRgbNear(tuple3(result.output, "Reflectance", 0), White[0], White[1] * 128 / 255.0, 0, 1e-6);
  expectRgbNear(tuple3(result.output, "Reflectance", 3), Red[0], Red[1], Red[2], 1e-6);
}

TEST(SceneReader, GltfVertexColoursMultiplyTheFactorBeforeItIsClamped)
{
  // A primitive without a material (white, as glTF's default material is) coloured by
  // COLOR_0 (51, 102, 153): its cells reflect (0.2, 0.4, 0.6), as the file says. The factor
  // was clamped to 0.99 first, with a warning of a reflectance of 1 that no cell had, and the
  // colours read 1% dark (0.198, 0.396, 0.594): a model painted by vertex colours alone.
  const TestFolder scratch("gltf-colours-default");
  const fs::path& folder = scratch.path;
  std::string json = gltfJsonWithVertexColour(std::string("\x33\x66\x99\xff", 4));
  replaceOnce(json, R"("POSITION": 0}, "indices": 1, "material": 0,)",
    R"("POSITION": 0, "COLOR_0": 3}, "indices": 1,)");
  writeFile(folder / "colours.gltf", json);
  const ReadResult result = readScene(folder / "colours.gltf");
  ASSERT_TRUE(result.succeeded) << result.errors();
  expectRgbNear(tuple3(result.output, "Reflectance", 0), 0.2, 0.4, 0.6, 1e-12);
  expectRgbNear(tuple3(result.output, "Reflectance", 3), Red[0], Red[1], Red[2], 1e-12);
  EXPECT_EQ(result.warnings(), "");

  // The same default material on a primitive without colours is clamped, with its warning.
  std::string uncoloured = json;
  replaceOnce(uncoloured, R"("indices": 2, "material": 1,)", R"("indices": 2,)");
  writeFile(folder / "uncoloured.gltf", uncoloured);
  const ReadResult mixed = readScene(folder / "uncoloured.gltf");
  ASSERT_TRUE(mixed.succeeded) << mixed.errors();
  expectRgbNear(tuple3(mixed.output, "Reflectance", 0), 0.2, 0.4, 0.6, 1e-12);
  expectRgbNear(tuple3(mixed.output, "Reflectance", 3), 0.99, 0.99, 0.99, 0);
  EXPECT_NE(mixed.warnings().find("the glTF default material"), std::string::npos)
    << mixed.warnings();
}

TEST(SceneReader, AbortGivesAnEmptyOutputAndTheNextUpdateReads)
{
  const TestFolder scratch("abort");
  const fs::path& folder = scratch.path;
  writeFile(folder / "scene.obj", twoMaterialObj(""));
  auto reader = vtkSmartPointer<vtkRadiositySceneReader>::New();
  reader->SetFileName((folder / "scene.obj").string().c_str());
  auto messages = vtkSmartPointer<MessageRecorder>::New();
  messages->watch(reader);
  reader->SetAbortExecute(1);
  reader->Update();
  EXPECT_EQ(reader->GetOutput()->GetNumberOfCells(), 0);
  EXPECT_NE(messages->allErrors().find("aborted"), std::string::npos) << messages->allErrors();
  reader->Modified();
  reader->Update();
  EXPECT_EQ(reader->GetOutput()->GetNumberOfCells(), 4);
}

/// An n x n grid of unit quads at z = 0 without materials: about 2 n^2 lines, so that the
/// reader reports progress on the way (every 65,536 lines).
std::string gridObj(int n)
{
  std::string text;
  for (int j = 0; j <= n; ++j)
  {
    for (int i = 0; i <= n; ++i)
    {
      text += "v " + std::to_string(i) + " " + std::to_string(j) + " 0\n";
    }
  }
  for (int j = 0; j < n; ++j)
  {
    for (int i = 0; i < n; ++i)
    {
      const int corner = j * (n + 1) + i + 1; // OBJ counts from 1
      text += "f " + std::to_string(corner) + " " + std::to_string(corner + 1) + " " +
        std::to_string(corner + n + 2) + " " + std::to_string(corner + n + 1) + "\n";
    }
  }
  return text;
}

TEST(SceneReader, NoProgressIsReportedAfterAnAbort)
{
  // As for the filter (FilterBadInput.NoProgressIsReportedAfterAnAbort): VTK's executive
  // reports 1.0 at the end of every execution, aborted or not, which ParaView shows as a
  // finished read.
  const TestFolder scratch("abort-progress");
  const fs::path file = scratch.path / "grid.obj";
  writeFile(file, gridObj(400));
  auto reader = vtkSmartPointer<vtkRadiositySceneReader>::New();
  reader->SetFileName(file.string().c_str());
  ProgressLog log;
  log.threshold = 0.2;
  vtkNew<vtkCallbackCommand> command;
  logProgress(reader, log, command);
  auto messages = vtkSmartPointer<MessageRecorder>::New();
  messages->watch(reader);
  reader->Update();
  ASSERT_TRUE(log.aborted) << listed(log.values, 0);
  EXPECT_EQ(log.values.size(), log.abortedAfter)
    << "reported after the abort: " << listed(log.values, log.abortedAfter);
  for (double value : log.values)
  {
    EXPECT_LT(value, 1.0) << listed(log.values, 0);
  }
  EXPECT_NE(messages->allErrors().find("aborted"), std::string::npos) << messages->allErrors();
  EXPECT_DOUBLE_EQ(reader->GetProgress(), log.values.back());
  EXPECT_EQ(reader->GetOutput()->GetNumberOfCells(), 0);

  // An abort asked for before the update stops it before anything is reported: the update
  // runs (the reader is modified) and fails as aborted again.
  log.values.clear();
  messages->errors.clear();
  reader->Modified();
  reader->SetAbortExecute(1);
  reader->Update();
  EXPECT_TRUE(log.values.empty()) << listed(log.values, 0);
  EXPECT_EQ(reader->GetOutput()->GetNumberOfCells(), 0);
  EXPECT_NE(messages->allErrors().find("aborted"), std::string::npos) << messages->allErrors();

  // A read that runs to its end still reports its progress from 0 to 1.0.
  reader->Modified();
  log.values.clear();
  reader->Update();
  ASSERT_FALSE(log.values.empty());
  EXPECT_EQ(log.values.front(), 0.0);
  EXPECT_EQ(log.values.back(), 1.0);
  EXPECT_EQ(reader->GetOutput()->GetNumberOfCells(), 400 * 400);
  reader->RemoveAllObservers();
}

// --- Bad input: an error naming the file and what is wrong, an empty output -------------------

struct BadFile
{
  const char* name;
  std::string content;
  const char* expected; ///< a piece of the error
};

TEST(SceneReader, BadFilesGiveAnErrorNamingTheFileAndAnEmptyOutput)
{
  const TestFolder scratch("bad");
  const fs::path& folder = scratch.path;
  const std::string buffer = gltfBuffer();
  std::string lines = gltfJson(dataUri(buffer), "", "[0, 0, 0]", 1);
  std::string points = gltfJson(dataUri(buffer), "", "[0, 0, 0]", 0);
  std::string outside = gltfJson(dataUri(buffer));
  replaceOnce(outside, R"("count": 8)", R"("count": 9)");
  std::string cycle = gltfJson(dataUri(buffer));
  replaceOnce(cycle, R"({"mesh": 0})", R"({"mesh": 0, "children": [0]})");
  std::string glb = glbFile(gltfJson(""), buffer);
  std::string draco = gltfJson(dataUri(buffer));
  replaceOnce(draco, R"("scene": 0,)",
    R"("scene": 0, "extensionsRequired": ["KHR_draco_mesh_compression"],)");
  std::string version1 = gltfJson(dataUri(buffer));
  replaceOnce(version1, R"("version": "2.0")", R"("version": "1.0")");
  std::string notBase64 = gltfJson("data:application/octet-stream;base64,#!");
  const std::vector<BadFile> files = {
    { "lines.gltf", lines, "only points or lines" },
    { "points.gltf", points, "only points or lines" },
    { "broken.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [", "is not valid JSON" },
    { "outside.gltf", outside, "accessors[0]" },
    { "cycle.gltf", cycle, "cycle through node" },
    { "truncated.glb", glb.substr(0, glb.size() - 10), "truncated or damaged" },
    { "empty.gltf", R"({"asset": {"version": "2.0"}})", "no triangles" },
    { "draco.gltf", draco, "requires the extension KHR_draco_mesh_compression" },
    { "version1.gltf", version1, "glTF version 1.0, not 2.x" },
    { "noscenes.gltf", R"({"asset": {"version": "2.0"}, "scene": 0})",
      "noscenes.gltf': scene = 0 but the file has 0 scenes" },
    { "nobin.gltf", gltfJson("missing.bin"), "missing.bin', which does not exist" },
    { "huge.gltf", gltfJson("huge.bin"), "huge.bin' is over the 4 GiB this reader takes" },
    { "base64.gltf", notBase64, "not base64" },
    { "index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "line 4: a face names vertex 4" },
    { "negative.obj", "v 0 0 0\nf -1 -2 -3\n", "names vertex -2" },
    { "word.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", "'x' is not a vertex reference" },
    { "nan.obj", "v 0 nan 0\n", "line 1: 'v 0 nan 0' is not a vertex" },
    { "lines.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n", "has no faces" },
    { "badkd.obj", "mtllib badkd.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n",
      "'Kd red' is not a colour" },
    { "notply.ply", "solid cube\n", "does not start with 'ply'" },
    { "novertex.ply",
      "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int "
      "vertex_indices\nend_header\n3 0 1 2\n",
      "no element 'vertex'" },
    { "short.ply",
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float "
      "z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n",
      "truncated" },
    { "faceindex.ply",
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float "
      "z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 "
      "0 1 7\n",
      "names vertex 7" },
    { "scene.stl", "solid x\nendsolid x\n", "extension '.stl'" },
  };
  writeFile(folder / "badkd.mtl", "newmtl m\nKd red\n");
  // A sparse 5 GiB buffer: refused by its size, before a byte is read.
  writeFile(folder / "huge.bin", "");
  fs::resize_file(folder / "huge.bin", std::uintmax_t(5) << 30);
  for (const BadFile& file : files)
  {
    SCOPED_TRACE(file.name);
    writeFile(folder / file.name, file.content);
    const ReadResult result = readScene(folder / file.name);
    EXPECT_FALSE(result.succeeded);
    ASSERT_FALSE(result.messages->errors.empty());
    EXPECT_NE(result.errors().find((folder / file.name).string()), std::string::npos)
      << result.errors();
    EXPECT_NE(result.errors().find(file.expected), std::string::npos) << result.errors();
    EXPECT_EQ(result.output->GetNumberOfCells(), 0);
    EXPECT_EQ(result.output->GetNumberOfPoints(), 0);
  }
}

TEST(SceneReader, PlyTriangleStripsWithBadIndicesOrCountsAreRefused)
{
  const TestFolder scratch("ply-bad-strips");
  const fs::path& folder = scratch.path;
  // A binary list of 2^30 indices in a file of a few hundred bytes.
  std::string huge = stripHeader("binary_big_endian", "", "");
  huge.append(6 * 12, '\0');
  appendBigEndian(huge, 1u << 30);
  appendBigEndian(huge, 0);
  // A list the file holds but the memory limit does not: 20,000 indices, up to 19,998
  // triangles (about 2 MiB of output) over 1 MiB.
  std::string long_ = stripHeader("binary_big_endian", "", "");
  for (const auto& corner : StripCorners)
  {
    for (float coordinate : corner)
    {
      std::uint32_t bits;
      std::memcpy(&bits, &coordinate, 4);
      appendBigEndian(long_, bits);
    }
  }
  appendBigEndian(long_, 20000);
  for (int i = 0; i < 20000; ++i)
  {
    appendBigEndian(long_, static_cast<std::uint32_t>(i % 6));
  }
  std::string fraction = asciiStripFile({ 0, 1, 2 });
  fraction.replace(fraction.rfind(" 2\n"), 2, " 2.5");
  std::string truncated = asciiStripFile({ 0, 1, 2, 3, 4, 5 });
  truncated.resize(truncated.size() - 6);
  std::string beforeVertices = "ply\nformat ascii 1.0\nelement tristrips 1\nproperty list int int "
                               "vertex_indices\nelement vertex 3\nproperty float x\nproperty "
                               "float y\nproperty float z\nend_header\n3 0 1 2\n0 0 0\n1 0 0\n"
                               "0 1 0\n";
  const std::vector<BadFile> files = {
    { "outside.ply", asciiStripFile({ 0, 1, 2, 6 }), "names vertex 6 in tristrips 0 but has 6" },
    { "negative.ply", asciiStripFile({ 0, 1, 2, -2 }), "names vertex -2 in tristrips 0" },
    { "fraction.ply", fraction, "names vertex 2.5" },
    { "huge.ply", huge, "has a list of 1.07374e+09 values in tristrips 0, more than the file's" },
    { "truncated.ply", truncated, "truncated" },
    { "short.ply", asciiStripFile({ 0, 1, -1, 2, 3, -1 }), "no triangle in its strips" },
    { "flat.ply", asciiStripFile({ 0, 1, 0, 1, 0 }), "no triangle in its strips" },
    { "before.ply", beforeVertices, "lists its triangle strips before its vertices" },
  };
  for (const BadFile& file : files)
  {
    SCOPED_TRACE(file.name);
    writeFile(folder / file.name, file.content);
    const ReadResult result = readScene(folder / file.name);
    EXPECT_FALSE(result.succeeded);
    EXPECT_NE(result.errors().find((folder / file.name).string()), std::string::npos)
      << result.errors();
    EXPECT_NE(result.errors().find(file.expected), std::string::npos) << result.errors();
    EXPECT_EQ(result.output->GetNumberOfCells(), 0);
  }

  writeFile(folder / "long.ply", long_);
  auto reader = vtkSmartPointer<vtkRadiositySceneReader>::New();
  auto messages = vtkSmartPointer<MessageRecorder>::New();
  messages->watch(reader);
  reader->SetFileName((folder / "long.ply").string().c_str());
  reader->SetMemoryLimit(1);
  EXPECT_EQ(reader->GetExecutive()->Update(), 0);
  EXPECT_NE(messages->allErrors().find("over the memory limit"), std::string::npos)
    << messages->allErrors();
  EXPECT_NE(messages->allErrors().find("20000 triangles"), std::string::npos)
    << messages->allErrors();
  reader->SetMemoryLimit(0);
  EXPECT_EQ(reader->GetExecutive()->Update(), 1) << messages->allErrors();
  EXPECT_EQ(reader->GetOutput()->GetNumberOfCells(), 19998);
}

TEST(SceneReader, MissingFileAndNoFileNameAreErrors)
{
  const TestFolder scratch("missing");
  const fs::path& folder = scratch.path;
  const ReadResult missing = readScene(folder / "nowhere.obj");
  EXPECT_FALSE(missing.succeeded);
  EXPECT_NE(missing.errors().find("nowhere.obj' does not exist"), std::string::npos)
    << missing.errors();

  auto reader = vtkSmartPointer<vtkRadiositySceneReader>::New();
  auto messages = vtkSmartPointer<MessageRecorder>::New();
  messages->watch(reader);
  EXPECT_EQ(reader->GetExecutive()->Update(), 0);
  EXPECT_NE(messages->allErrors().find("no FileName"), std::string::npos) << messages->allErrors();
  EXPECT_EQ(reader->GetOutput()->GetNumberOfCells(), 0);

  EXPECT_TRUE(vtkRadiositySceneReader::CanReadFile("a/B.OBJ"));
  EXPECT_TRUE(vtkRadiositySceneReader::CanReadFile("scene.glb"));
  EXPECT_FALSE(vtkRadiositySceneReader::CanReadFile("scene.stl"));
}

TEST(SceneReader, ABadFileAfterAGoodOneLeavesNoStaleOutput)
{
  const TestFolder scratch("stale");
  const fs::path& folder = scratch.path;
  writeFile(folder / "good.obj", twoMaterialObj(""));
  writeFile(folder / "bad.obj", "v 0 0 0\nf 1 2 3\n");
  auto reader = vtkSmartPointer<vtkRadiositySceneReader>::New();
  auto messages = vtkSmartPointer<MessageRecorder>::New();
  messages->watch(reader);
  reader->SetFileName((folder / "good.obj").string().c_str());
  reader->Update();
  EXPECT_EQ(reader->GetOutput()->GetNumberOfCells(), 4);
  EXPECT_NE(messages->allWarnings().find("no material library"), std::string::npos);
  reader->SetFileName((folder / "bad.obj").string().c_str());
  reader->Update();
  EXPECT_FALSE(messages->errors.empty());
  EXPECT_EQ(reader->GetOutput()->GetNumberOfCells(), 0);
}
