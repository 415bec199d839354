#include "FileChecks.h"

#include "GuardedRead.h"
#include "MemoryBudget.h"
#include "TextLines.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

namespace mlr::guarded
{

namespace
{
/// An OBJ file's logical lines, read from its path.
class ObjLines
{
public:
  explicit ObjLines(const std::string& path)
    : File(path, std::ios::binary)
    , Lines(File)
  {
  }
  bool next(std::string& line) { return this->Lines.next(line); }
  std::size_t number() const { return this->Lines.number(); }

private:
  std::ifstream File;
  LogicalLines Lines;
};

/// One index of an OBJ reference (v, vt or vn): 1-based, or negative from the last defined.
bool parseIndex(const std::string& text, long long& value)
{
  if (text.empty())
  {
    return false;
  }
  errno = 0;
  char* end = nullptr;
  value = std::strtoll(text.c_str(), &end, 10);
  return errno == 0 && end == text.c_str() + text.size();
}
}

void checkObjFile(const std::string& path, const std::string& what)
{
  // First pass: how many vertices, texture coordinates and normals the file defines (a face
  // may name a vertex defined after it).
  long long totals[3] = { 0, 0, 0 };
  std::string line;
  {
    ObjLines lines(path);
    while (lines.next(line))
    {
      std::istringstream words(line);
      std::string keyword;
      words >> keyword;
      totals[0] += keyword == "v" ? 1 : 0;
      totals[1] += keyword == "vt" ? 1 : 0;
      totals[2] += keyword == "vn" ? 1 : 0;
    }
  }

  // Second pass: every reference of f, l and p. Negative indices count back from the last
  // element defined so far.
  static const char* const kinds[3] = { "vertex", "texture coordinate", "normal" };
  static const char* const keywords[3] = { "v", "vt", "vn" };
  long long sofar[3] = { 0, 0, 0 };
  ObjLines lines(path);
  while (lines.next(line))
  {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    for (int k = 0; k < 3; ++k)
    {
      sofar[k] += keyword == keywords[k] ? 1 : 0;
    }
    if (keyword != "f" && keyword != "l" && keyword != "p")
    {
      continue;
    }
    std::string reference;
    while (words >> reference)
    {
      // v, v/vt, v/vt/vn or v//vn
      std::vector<std::string> parts(1);
      for (char c : reference)
      {
        if (c == '/')
        {
          parts.emplace_back();
        }
        else
        {
          parts.back() += c;
        }
      }
      std::ostringstream problem;
      if (parts.size() > 3 || parts[0].empty())
      {
        problem << "'" << printable(reference)
                << "' is not a vertex reference (v, v/vt, v/vt/vn or v//vn)";
      }
      for (std::size_t k = 0; k < parts.size() && k < 3 && problem.str().empty(); ++k)
      {
        if (k > 0 && parts[k].empty())
        {
          continue; // v//vn or v/vt/
        }
        long long index = 0;
        if (!parseIndex(parts[k], index))
        {
          problem << "'" << printable(reference) << "' is not a vertex reference: '"
                  << printable(parts[k]) << "' is not a whole number";
        }
        else if (index == 0 || index > totals[k] || (index < 0 && -index > sofar[k]))
        {
          problem << "'" << printable(reference) << "' names " << kinds[k] << " " << index
                  << " but the file defines " << (index < 0 ? sofar[k] : totals[k])
                  << (index < 0 ? " before it" : "") << " (" << keywords[k] << " lines)";
        }
      }
      if (!problem.str().empty())
      {
        throw InputError(what + ", line " + std::to_string(lines.number()) + ": " + problem.str());
      }
    }
  }
}

void checkStlFile(const std::string& path, const std::string& what)
{
  std::ifstream in(path, std::ios::binary);
  char head[256] = {};
  in.read(head, sizeof(head));
  const std::size_t read = static_cast<std::size_t>(in.gcount());
  std::size_t start = 0;
  while (start < read && std::isspace(static_cast<unsigned char>(head[start])))
  {
    ++start;
  }
  bool text = read >= start + 5;
  for (std::size_t i = 0; text && i < 5; ++i)
  {
    text = std::tolower(static_cast<unsigned char>(head[start + i])) == "solid"[i];
  }
  for (std::size_t i = 0; text && i < read; ++i)
  {
    const unsigned char c = static_cast<unsigned char>(head[i]);
    text = c >= 0x20 || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
  }
  if (text)
  {
    return; // ASCII: read as text, nothing allocated from a count
  }
  in.clear();
  in.seekg(0, std::ios::end);
  const std::uint64_t size = static_cast<std::uint64_t>(in.tellg());
  if (size < 84)
  {
    throw InputError(what +
      " is not an STL file: too short for a binary STL header (84 bytes) "
      "and not ASCII STL text starting with 'solid'");
  }
  const std::uint64_t count = static_cast<std::uint8_t>(head[80]) |
    (static_cast<std::uint64_t>(static_cast<std::uint8_t>(head[81])) << 8) |
    (static_cast<std::uint64_t>(static_cast<std::uint8_t>(head[82])) << 16) |
    (static_cast<std::uint64_t>(static_cast<std::uint8_t>(head[83])) << 24);
  if (84 + 50 * count > size)
  {
    throw InputError(what + " is a binary STL file whose header counts " + std::to_string(count) +
      " triangles, but it holds only " + std::to_string((size - 84) / 50) +
      " (50 bytes each after an 84-byte header): it is truncated or damaged");
  }
}

namespace
{
/// Bytes of one value of a PLY scalar type, 0 for a name PLY does not know.
int plySize(const std::string& type)
{
  static const std::pair<const char*, int> types[] = { { "char", 1 }, { "uchar", 1 }, { "int8", 1 },
    { "uint8", 1 }, { "short", 2 }, { "ushort", 2 }, { "int16", 2 }, { "uint16", 2 }, { "int", 4 },
    { "uint", 4 }, { "int32", 4 }, { "uint32", 4 }, { "float", 4 }, { "float32", 4 },
    { "double", 8 }, { "float64", 8 } };
  for (const auto& [name, size] : types)
  {
    if (type == name)
    {
      return size;
    }
  }
  return 0;
}
}

void checkPlyFile(const std::string& path, const std::string& what)
{
  std::ifstream in(path, std::ios::binary);
  auto fail = [&](const std::string& problem)
  { throw InputError(what + " is not a PLY file VTK can read: " + problem); };
  std::string line;
  if (!std::getline(in, line) || line.rfind("ply", 0) != 0)
  {
    fail("it does not start with 'ply'");
  }
  struct Element
  {
    std::string name;
    std::uint64_t count = 0;
    std::uint64_t fixedBytes = 0; ///< scalar properties, plus the count of each list
    std::uint64_t values = 0;     ///< values per element (a list counts one)
    std::vector<std::string> scalars;
  };
  std::vector<Element> elements;
  std::string format;
  bool ended = false;
  std::size_t lines = 1;
  while (!ended && std::getline(in, line))
  {
    if (++lines > 10000)
    {
      fail("its header has no end_header in its first 10000 lines");
    }
    if (!line.empty() && line.back() == '\r')
    {
      line.pop_back();
    }
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "format")
    {
      std::string version;
      words >> format >> version;
      if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
      {
        fail("unknown format '" + printable(format) + "'");
      }
    }
    else if (keyword == "element")
    {
      Element element;
      std::string count;
      words >> element.name >> count;
      if (element.name.empty() || count.empty() ||
        count.find_first_not_of("0123456789") != std::string::npos || count.size() > 12)
      {
        fail("bad element line '" + printable(line) + "'");
      }
      element.count = std::stoull(count);
      elements.push_back(element);
    }
    else if (keyword == "property")
    {
      if (elements.empty())
      {
        fail("a property comes before any element");
      }
      std::string type, name;
      words >> type;
      if (type == "list")
      {
        std::string countType, itemType;
        words >> countType >> itemType >> name;
        if (plySize(countType) == 0 || plySize(itemType) == 0 || name.empty())
        {
          fail("bad list property '" + printable(line) + "'");
        }
        elements.back().fixedBytes += static_cast<std::uint64_t>(plySize(countType));
      }
      else
      {
        words >> name;
        if (plySize(type) == 0 || name.empty())
        {
          fail("bad property '" + printable(line) + "'");
        }
        elements.back().fixedBytes += static_cast<std::uint64_t>(plySize(type));
        elements.back().scalars.push_back(name);
      }
      ++elements.back().values;
    }
    else if (keyword == "end_header")
    {
      ended = true;
    }
    else if (keyword != "comment" && keyword != "obj_info" && !keyword.empty())
    {
      fail("unknown header line '" + printable(line) + "'");
    }
  }
  if (!ended || format.empty())
  {
    fail(ended ? "no format line" : "its header does not end (end_header)");
  }
  const Element* vertex = nullptr;
  for (const Element& e : elements)
  {
    vertex = e.name == "vertex" ? &e : vertex;
  }
  for (const char* axis : { "x", "y", "z" })
  {
    if (!vertex ||
      std::find(vertex->scalars.begin(), vertex->scalars.end(), axis) == vertex->scalars.end())
    {
      fail("no element 'vertex' with properties x, y and z");
    }
  }
  // The data must be able to hold what the header counts: at least the fixed bytes of every
  // element (binary), or one character and a separator per value (ASCII).
  const std::uint64_t headerEnd = static_cast<std::uint64_t>(in.tellg());
  in.seekg(0, std::ios::end);
  const std::uint64_t rest = static_cast<std::uint64_t>(in.tellg()) - headerEnd;
  std::uint64_t needed = 0;
  for (const Element& e : elements)
  {
    needed = saturatingSum(needed,
      saturatingProduct(
        e.count, format == "ascii" ? saturatingProduct(2, e.values) : e.fixedBytes));
  }
  if (needed > saturatingSum(rest, 1))
  {
    std::ostringstream s;
    s << "its header counts elements that need at least " << static_cast<double>(needed)
      << " bytes but only " << rest << " follow it: it is truncated or damaged";
    fail(s.str());
  }
}

} // namespace mlr::guarded
