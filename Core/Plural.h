// A count and its noun for messages, so that none says "1 polygons" or "2 polygon".
#pragma once

#include <cstddef>
#include <string>

namespace mlr
{

/// "1 polygon", "2 polygons"; `nouns` for a plural that is not the noun and an s.
inline std::string countOf(std::size_t n, const std::string& noun, const std::string& nouns = {})
{
  return std::to_string(n) + " " + (n == 1 ? noun : (nouns.empty() ? noun + "s" : nouns));
}

} // namespace mlr
