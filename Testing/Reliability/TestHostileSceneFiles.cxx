// vtkRadiositySceneReader in the calling process, as ParaView and VTK Python run it, on files
// built to crash, hang or exhaust a reader: each is refused with an error that names the file
// and the defect, and nothing else happens (the sanitizer build runs these too).
#include "FilterTestSupport.h"

#include "vtkExecutive.h"
#include "vtkPolyData.h"
#include "vtkRadiositySceneReader.h"
#include "vtkSmartPointer.h"

#include <gtest/gtest.h>

#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

using namespace mlr::testing;

namespace
{
namespace fs = std::filesystem;

struct Outcome
{
  bool read = false;
  std::string errors, warnings;
};

Outcome readScene(const fs::path& path, int memoryLimitMiB = 0)
{
  auto reader = vtkSmartPointer<vtkRadiositySceneReader>::New();
  reader->SetFileName(path.string().c_str());
  reader->SetMemoryLimit(memoryLimitMiB);
  auto messages = vtkSmartPointer<MessageRecorder>::New();
  messages->watch(reader);
  Outcome outcome;
  outcome.read = reader->GetExecutive()->Update() != 0;
  outcome.errors = messages->allErrors();
  outcome.warnings = messages->allWarnings();
  return outcome;
}

fs::path hostile(const std::string& name)
{
  return fs::path(MLR_HOSTILE_DIR) / name;
}

/// A glTF file with one triangle mesh (its buffer a data: URI) and the JSON array `nodes`,
/// some of which draw mesh 0; `sceneNodes` lists the roots.
std::string gltfWithNodes(const std::string& nodes, const std::string& sceneNodes)
{
  // Three float VEC3 positions (0,0,0) (1,0,0) (0,1,0), then uint16 indices 0 1 2 and padding.
  const std::string buffer = "data:application/octet-stream;base64,"
                             "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA=";
  return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": )" + sceneNodes +
    R"(}], "nodes": )" + nodes +
    R"(, "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "buffers": [{"byteLength": 44, "uri": ")" +
    buffer + R"("}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36,
    "byteLength": 6}], "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3,
    "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}, {"bufferView": 1,
    "componentType": 5123, "count": 3, "type": "SCALAR"}]})";
}

void expectRefused(const std::string& file, const std::string& reason)
{
  const Outcome outcome = readScene(hostile(file));
  EXPECT_FALSE(outcome.read) << file;
  EXPECT_NE(outcome.errors.find(file), std::string::npos) << outcome.errors;
  EXPECT_NE(outcome.errors.find(reason), std::string::npos) << outcome.errors;
}
} // namespace

TEST(HostileSceneFiles, OffsetsNear2To63AreOutOfTheirBufferNotAnOverflow)
{
  expectRefused("gltf_bufferview_offset_overflow_segv.gltf", "does not fit in buffer");
  expectRefused("glb_bufferview_offset_overflow_segv.glb", "does not fit in buffer");
}

TEST(HostileSceneFiles, JsonNestedPastTheDepthLimitIsRefusedBeforeParsing)
{
  expectRefused("gltf_deep_json_in_material_extensions_stack_overflow.gltf", "levels deep");
}

TEST(HostileSceneFiles, BuffersNamingOneFileManyTimesReadItOnce)
{
  // 20,000 buffers name the file itself: read once, the file is refused for what it is (JSON
  // text, not vertex data) rather than held 20,000 times.
  const Outcome outcome = readScene(hostile("gltf_self_referencing_buffers_x20000_memory.gltf"));
  if (!outcome.read)
  {
    EXPECT_NE(
      outcome.errors.find("gltf_self_referencing_buffers_x20000_memory.gltf"), std::string::npos)
      << outcome.errors;
  }
}

TEST(HostileSceneFiles, AFaceIndexOfLlongMinIsRefusedByLine)
{
  expectRefused("obj_face_index_llong_min.obj", "names vertex -9223372036854775808");
}

TEST(HostileSceneFiles, APlyElementWithoutPropertiesIsRefusedAtOnce)
{
  expectRefused("ply_element_without_properties_infinite_loop.ply", "but no properties");
}

TEST(HostileSceneFiles, AJpegWhoseFrameHeaderHidesBehindAStrayByteIsStillMeasured)
{
  const Outcome outcome = readScene(hostile("mtl_map_kd_jpeg_junk_byte_20000x20000.obj"));
  EXPECT_NE((outcome.errors + outcome.warnings).find("larger than 64 Mpixels"), std::string::npos)
    << outcome.errors << outcome.warnings;
}

TEST(HostileSceneFiles, RowCountsLargerThanTheFileAreRefused)
{
  TestFolder folder("ply-count");
  const fs::path ply = folder.path / "huge.ply";
  std::ofstream(ply) << "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000000000\n"
                        "property float x\nproperty float y\nproperty float z\nelement face 1\n"
                        "property list uchar int vertex_indices\nend_header\n";
  const Outcome outcome = readScene(ply);
  EXPECT_FALSE(outcome.read);
  EXPECT_NE(outcome.errors.find("more than the file's"), std::string::npos) << outcome.errors;
}

TEST(HostileSceneFiles, APipeIsRefusedWithoutOpeningIt)
{
  // Opening a FIFO for reading blocks until a writer comes: this test would hang, and ctest's
  // timeout fail it, if the reader opened it.
  TestFolder folder("fifo");
  const fs::path fifo = folder.path / "scene.obj";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const Outcome outcome = readScene(fifo);
  EXPECT_FALSE(outcome.read);
  EXPECT_NE(outcome.errors.find("not a regular file"), std::string::npos) << outcome.errors;
}

TEST(HostileSceneFiles, AnEmissionBeyondDoubleIsRefusedNotInfinite)
{
  TestFolder folder("ke");
  std::ofstream(folder.path / "hot.mtl") << "newmtl hot\nKd 0.5 0.5 0.5\nKe 1e308 0 0\n";
  std::ofstream(folder.path / "hot.obj")
    << "mtllib hot.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl hot\nf 1 2 3\n";
  const Outcome outcome = readScene(folder.path / "hot.obj");
  EXPECT_FALSE(outcome.read);
  EXPECT_NE(outcome.errors.find("emission too large"), std::string::npos) << outcome.errors;
}

TEST(HostileSceneFiles, InstancesBeyondTheMemoryLimitAreRefusedBeforeDrawing)
{
  // One root with 100,000 children, each drawing the mesh: 100,000 triangles, an estimated
  // 18 MiB, over a limit of 8 MiB and within the default.
  constexpr int Instances = 100000;
  std::ostringstream nodes;
  nodes << "[{\"children\": [";
  for (int i = 1; i <= Instances; ++i)
  {
    nodes << (i > 1 ? "," : "") << i;
  }
  nodes << "]}";
  for (int i = 1; i <= Instances; ++i)
  {
    nodes << ",{\"mesh\": 0}";
  }
  nodes << "]";
  TestFolder folder("instances");
  const fs::path gltf = folder.path / "instances.gltf";
  std::ofstream(gltf) << gltfWithNodes(nodes.str(), "[0]");
  const Outcome limited = readScene(gltf, 8);
  EXPECT_FALSE(limited.read);
  EXPECT_NE(limited.errors.find("100000 triangles"), std::string::npos) << limited.errors;
  EXPECT_NE(limited.errors.find("memory limit"), std::string::npos) << limited.errors;
  EXPECT_TRUE(readScene(gltf).read);
}

TEST(HostileSceneFiles, AnObjOverTheLimitIsRefusedWithBoundsFromItsSize)
{
  // An OBJ's counts are not known before reading it: the refusal gives them as bounds from
  // the file's size, not as counts, and names both ways to raise the limit.
  TestFolder folder("obj-limit");
  const fs::path obj = folder.path / "big.obj";
  {
    std::ofstream out(obj);
    for (int i = 0; i < 160000; ++i)
    {
      out << "v 0 0 0\n";
    }
  }
  const Outcome limited = readScene(obj, 8);
  EXPECT_FALSE(limited.read);
  EXPECT_NE(limited.errors.find("up to 80000 points and up to 80000 triangles (bounds from the "
                                "file's size)"),
    std::string::npos)
    << limited.errors;
  EXPECT_NE(limited.errors.find("--memory-limit"), std::string::npos) << limited.errors;
}

TEST(HostileSceneFiles, ALongNodeChainIsCheckedInLinearTime)
{
  // 200,000 nodes, each the parent of the next, the mesh at the end: climbing the chain once
  // from every node (2 x 10^10 steps) would run into the test's timeout.
  constexpr int Chain = 200000;
  std::ostringstream nodes;
  nodes << "[";
  for (int i = 0; i < Chain - 1; ++i)
  {
    nodes << "{\"children\": [" << i + 1 << "]},";
  }
  nodes << "{\"mesh\": 0}]";
  TestFolder folder("chain");
  const fs::path gltf = folder.path / "chain.gltf";
  std::ofstream(gltf) << gltfWithNodes(nodes.str(), "[0]");
  const Outcome outcome = readScene(gltf);
  EXPECT_TRUE(outcome.read) << outcome.errors;
}

TEST(HostileSceneFiles, AMaterialLibraryNamedOnManyLinesIsReadOnce)
{
  // 20,000 mtllib lines name one library that does not exist: one warning, not 20,000
  // (and for a library that exists, one reading).
  TestFolder folder("mtllib");
  std::ofstream obj(folder.path / "many.obj");
  for (int i = 0; i < 20000; ++i)
  {
    obj << "mtllib missing.mtl\n";
  }
  obj << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  obj.close();
  const Outcome outcome = readScene(folder.path / "many.obj");
  EXPECT_TRUE(outcome.read) << outcome.errors;
  std::size_t warnings = 0;
  for (std::size_t at = outcome.warnings.find("missing.mtl"); at != std::string::npos;
       at = outcome.warnings.find("missing.mtl", at + 1))
  {
    ++warnings;
  }
  EXPECT_EQ(warnings, 1u) << outcome.warnings.substr(0, 2000);
}
