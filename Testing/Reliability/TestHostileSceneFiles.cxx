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

Outcome readScene(const fs::path& path)
{
  auto reader = vtkSmartPointer<vtkRadiositySceneReader>::New();
  reader->SetFileName(path.string().c_str());
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

struct TestFolder
{
  explicit TestFolder(const std::string& name)
    : path(fs::temp_directory_path() / ("mlr-hostile-" + name))
  {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TestFolder()
  {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
  const fs::path path;
};

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
