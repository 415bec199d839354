#include "SceneText.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <system_error>

namespace mlr::scenefile
{

std::string named(const std::string& text)
{
  return "'" + text + "'";
}

std::string trim(const std::string& text)
{
  const auto first = text.find_first_not_of(" \t\r\n\f\v");
  if (first == std::string::npos)
  {
    return {};
  }
  return text.substr(first, text.find_last_not_of(" \t\r\n\f\v") - first + 1);
}

std::vector<std::string> words(const std::string& text)
{
  std::vector<std::string> result;
  std::istringstream in(text);
  std::string word;
  while (in >> word)
  {
    result.push_back(word);
  }
  return result;
}

bool parseNumber(const std::string& word, double& value)
{
  const char* first = word.data();
  const char* last = word.data() + word.size();
  if (first != last && *first == '+')
  {
    ++first;
  }
  const auto [end, error] = std::from_chars(first, last, value);
  return error == std::errc() && end == last && std::isfinite(value);
}

bool parseInteger(const std::string& word, long long& value)
{
  const char* first = word.data();
  const char* last = word.data() + word.size();
  if (first != last && *first == '+')
  {
    ++first;
  }
  const auto [end, error] = std::from_chars(first, last, value);
  return error == std::errc() && end == last;
}

std::uintmax_t fileSize(const std::string& path)
{
  std::error_code error;
  const auto size = std::filesystem::file_size(path, error);
  return error ? 0 : size;
}

std::ifstream openFile(const std::string& path, const std::string& kind)
{
  std::error_code error;
  if (!std::filesystem::exists(path, error))
  {
    throw FileError("the " + kind + " " + named(path) + " does not exist");
  }
  if (std::filesystem::is_directory(path, error))
  {
    throw FileError("the " + kind + " " + named(path) + " is a folder, not a file");
  }
  // Opening a FIFO blocks until a writer appears, and a device never ends: only regular
  // files (or links to them) are read.
  if (!std::filesystem::is_regular_file(path, error))
  {
    throw FileError("the " + kind + " " + named(path) +
      " is not a regular file (a pipe, socket or device): save the scene to a file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in)
  {
    throw FileError(
      "the " + kind + " " + named(path) + " cannot be opened: " + std::strerror(errno));
  }
  return in;
}

} // namespace mlr::scenefile
