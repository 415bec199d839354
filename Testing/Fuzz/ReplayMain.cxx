// main() for the fuzz targets in builds without libFuzzer (Release, gcc's sanitizer build):
// runs every file given, or every file under the directories given, through
// LLVMFuzzerTestOneInput once. ctest replays the seed corpus and the crash regressions this
// way, so a fixed crash stays fixed in every build. Fails when no input was found.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace fs = std::filesystem;

int main(int argc, char** argv)
{
  std::vector<fs::path> inputs;
  for (int i = 1; i < argc; ++i)
  {
    const fs::path path = argv[i];
    if (fs::is_directory(path))
    {
      for (const auto& entry : fs::recursive_directory_iterator(path))
      {
        if (entry.is_regular_file() && entry.path().filename().string()[0] != '.')
        {
          inputs.push_back(entry.path());
        }
      }
    }
    else if (fs::is_regular_file(path))
    {
      inputs.push_back(path);
    }
    else
    {
      std::fprintf(stderr, "replay: no such file or directory: %s\n", argv[i]);
      return 1;
    }
  }
  if (inputs.empty())
  {
    std::fprintf(stderr, "replay: no input to run\n");
    return 1;
  }
  std::sort(inputs.begin(), inputs.end());
  for (const fs::path& path : inputs)
  {
    std::ifstream file(path, std::ios::binary);
    const std::vector<char> bytes(
      (std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    std::fprintf(stderr, "replay: %s (%zu bytes)\n", path.string().c_str(), bytes.size());
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  }
  std::printf("replayed %zu inputs\n", inputs.size());
  return 0;
}
