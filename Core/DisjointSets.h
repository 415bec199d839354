// Disjoint sets (union-find) over 0..n-1, for grouping what touches: surfaces of a mesh,
// corners that shade smoothly, faces of a floor.
#pragma once

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

namespace mlr
{

/**
 * Union-find with path halving. A join puts the larger root under the smaller, so every
 * set's root is its smallest member whatever order the joins come in: groups numbered by
 * their roots come out the same for any order of the same joins.
 */
class DisjointSets
{
public:
  explicit DisjointSets(std::size_t n)
    : Parent(n)
  {
    std::iota(this->Parent.begin(), this->Parent.end(), std::size_t(0));
  }

  /// The smallest member of the set that holds `i`.
  std::size_t find(std::size_t i)
  {
    while (this->Parent[i] != i)
    {
      i = this->Parent[i] = this->Parent[this->Parent[i]];
    }
    return i;
  }

  void join(std::size_t a, std::size_t b)
  {
    a = this->find(a);
    b = this->find(b);
    this->Parent[std::max(a, b)] = std::min(a, b);
  }

  std::size_t size() const { return this->Parent.size(); }

private:
  std::vector<std::size_t> Parent;
};

} // namespace mlr
