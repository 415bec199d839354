// Reading line-oriented text files the way their messages quote them: the logical lines of
// OBJ and MTL files (a backslash continues a line) and a line shown safely in an error. The
// scene reader and the command line's checks before reading share them, so that both count
// lines alike and a message names the same line number whichever refused the file.
#pragma once

#include <cstddef>
#include <istream>
#include <string>

namespace mlr
{

/// The logical lines of an OBJ or MTL file: a line ending in a backslash continues on the
/// next, a CR before the LF is dropped, and so is the UTF-8 byte order mark that Windows
/// editors put first (left in, it hid the first line's keyword, and a first 'v' line lost
/// shifted every vertex index after it). number() is the physical line last read, as
/// messages give it.
class LogicalLines
{
public:
  explicit LogicalLines(std::istream& in)
    : In(in)
  {
  }

  bool next(std::string& line)
  {
    line.clear();
    std::string part;
    bool any = false;
    while (std::getline(this->In, part))
    {
      any = true;
      ++this->Number;
      if (this->Number == 1 && part.rfind("\xEF\xBB\xBF", 0) == 0)
      {
        part.erase(0, 3);
      }
      if (!part.empty() && part.back() == '\r')
      {
        part.pop_back();
      }
      if (!part.empty() && part.back() == '\\')
      {
        part.back() = ' ';
        line += part;
        continue;
      }
      line += part;
      return true;
    }
    return any;
  }

  std::size_t number() const { return this->Number; }

private:
  std::istream& In;
  std::size_t Number = 0;
};

/// A piece of a file as messages show it: at most 60 characters, control bytes as '?', so
/// that a binary file given by mistake cannot garble the terminal.
inline std::string printable(const std::string& text)
{
  std::string shown = text.substr(0, 60);
  for (char& c : shown)
  {
    c = static_cast<unsigned char>(c) < 0x20 || c == 0x7f ? '?' : c;
  }
  return text.size() > 60 ? shown + "..." : shown;
}

} // namespace mlr
