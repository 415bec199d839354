// Reading a whole input file that Core parses itself (photometric and weather files): only
// regular files, so that a FIFO or a device given by mistake cannot block or never end, and
// never more than the bound its format could need.
#pragma once

#include <cstddef>
#include <string>

namespace mlr
{

/// What the messages call a kind of file and what they ask for instead.
struct FileKind
{
  std::string name; ///< "weather file"
  std::string give; ///< "an .epw file"
  std::size_t maximumBytes;
  std::string bound; ///< "the 32 MiB a year of hourly EPW records could need"
};

/// The whole of `path`; throws mlr::Error naming the file and what to fix.
std::string readRegularFile(const std::string& path, const FileKind& kind);

} // namespace mlr
