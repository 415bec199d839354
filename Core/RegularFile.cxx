#include "RegularFile.h"

#include "Error.h"

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace mlr
{

std::string readRegularFile(const std::string& path, const FileKind& kind)
{
  const std::string named = "the " + kind.name + " " + path;
  const std::string notRegular = named + " is not a regular file: give " + kind.give;
  struct stat info;
  if (::stat(path.c_str(), &info) != 0)
  {
    throw Error("cannot read " + named + ": " + std::strerror(errno));
  }
  if (!S_ISREG(info.st_mode))
  {
    throw Error(notRegular);
  }
  if (static_cast<std::uint64_t>(info.st_size) > kind.maximumBytes)
  {
    throw Error(named + " has " + std::to_string(info.st_size) + " bytes, more than " + kind.bound);
  }
  // Non-blocking, and checked again once open: the path may have been replaced by a FIFO
  // between stat() and open().
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0)
  {
    throw Error("cannot open " + named + ": " + std::strerror(errno));
  }
  struct stat opened;
  if (::fstat(fd, &opened) != 0 || !S_ISREG(opened.st_mode))
  {
    ::close(fd);
    throw Error(notRegular);
  }
  std::string text;
  char buffer[65536];
  for (;;)
  {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR)
    {
      continue;
    }
    if (n < 0)
    {
      const int error = errno;
      ::close(fd);
      throw Error("cannot read " + named + ": " + std::strerror(error));
    }
    if (n == 0)
    {
      break;
    }
    text.append(buffer, static_cast<std::size_t>(n));
    // The file may grow while it is read.
    if (text.size() > kind.maximumBytes)
    {
      ::close(fd);
      throw Error(named + " has more than " + kind.bound);
    }
  }
  ::close(fd);
  return text;
}

} // namespace mlr
