// CGAL 5.5's is_polygon_soup_a_polygon_mesh() (Polygon_mesh_processing/
// polygon_soup_to_polygon_mesh.h and orient_polygon_soup.h), restated on flat arrays so that
// a cancellation in the middle frees a few vectors rather than millions of set nodes.
//
// CGAL's three stages, and what they come to on triangles:
//  1. Every polygon has 3 or more corners, no corner twice, and no oriented edge (a, b)
//     appears twice in the soup (a std::set of all oriented edges).
//  2. It marks the edges with more than two incident polygons, counting both orientations,
//     and fails if any is marked. After stage 1 an edge has at most one polygon per
//     orientation, so none ever is: this stage cannot change the verdict.
//  3. has_singular_vertices() (true means "no singular vertex" and is the verdict): around
//     every vertex v it walks from the first incident polygon across the edges (v, x) to the
//     polygon holding (x, v), clockwise until it comes back or meets a border, then the
//     other way; a polygon around v that this walk did not reach means a second fan.
// Here the corners around each vertex are gathered by a counting sort, stage 1 becomes
// "no two corners of a vertex have the same next corner", and stage 3 the same walk over the
// vertex's corners. Which fan the walk starts from does not change whether there are two.
#include "ManifoldCheck.h"

#include <algorithm>
#include <utility>

namespace mlr::detail
{

namespace
{

/// A triangle seen from one of its corners v: the corner after v and the one before.
struct Corner
{
  std::size_t next;
  std::size_t prev;
};

constexpr std::size_t None = static_cast<std::size_t>(-1);

} // namespace

bool isTriangleSoupAPolygonMesh(const std::vector<SoupTriangle>& triangles, CancellationPoll& poll)
{
  if (triangles.empty())
  {
    return true;
  }

  // Stage 1, corners: a triangle with a corner twice fails.
  std::size_t maxId = 0;
  for (const SoupTriangle& t : triangles)
  {
    poll.tick();
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0])
    {
      return false;
    }
    maxId = std::max({ maxId, t[0], t[1], t[2] });
  }

  // Corners by vertex (counting sort): those of vertex v are corners[first[v], first[v + 1]).
  const std::size_t vertexCount = maxId + 1;
  std::vector<std::size_t> first(vertexCount + 1, 0);
  for (const SoupTriangle& t : triangles)
  {
    poll.tick();
    for (const std::size_t v : t)
    {
      ++first[v + 1];
    }
  }
  for (std::size_t v = 0; v < vertexCount; ++v)
  {
    poll.tick();
    first[v + 1] += first[v];
  }
  std::vector<Corner> corners(first.back());
  {
    std::vector<std::size_t> cursor(first.begin(), first.end() - 1);
    for (const SoupTriangle& t : triangles)
    {
      poll.tick();
      for (int k = 0; k < 3; ++k)
      {
        corners[cursor[t[k]]++] = { t[(k + 1) % 3], t[(k + 2) % 3] };
      }
    }
  }

  // Stage 1, oriented edges: (v, x) twice is two corners of v with the same next corner.
  const auto byNext = [](const Corner& a, const Corner& b) { return a.next < b.next; };
  for (std::size_t v = 0; v < vertexCount; ++v)
  {
    poll.tick();
    const auto begin = corners.begin() + static_cast<std::ptrdiff_t>(first[v]);
    const auto end = corners.begin() + static_cast<std::ptrdiff_t>(first[v + 1]);
    std::sort(begin, end, byNext);
    for (auto c = begin; c != end && c + 1 != end; ++c)
    {
      if (c->next == (c + 1)->next)
      {
        return false;
      }
    }
  }

  // Stage 3. Now every oriented edge is unique, so around v a corner has at most one
  // successor (the corner whose prev is its next: across the edge, clockwise) and at most one
  // predecessor: the fans are chains and cycles, and one walk covers the fan it starts in.
  std::vector<std::pair<std::size_t, std::size_t>> byPrev; // (prev, corner), reused
  for (std::size_t v = 0; v < vertexCount; ++v)
  {
    poll.tick();
    const std::size_t count = first[v + 1] - first[v];
    if (count <= 1)
    {
      continue;
    }
    const Corner* around = corners.data() + first[v];
    byPrev.clear();
    for (std::size_t i = 0; i < count; ++i)
    {
      byPrev.emplace_back(around[i].prev, i);
    }
    std::sort(byPrev.begin(), byPrev.end());
    const auto successor = [&](std::size_t i)
    {
      const auto it = std::lower_bound(
        byPrev.begin(), byPrev.end(), std::make_pair(around[i].next, std::size_t(0)));
      return it != byPrev.end() && it->first == around[i].next ? it->second : None;
    };
    const auto predecessor = [&](std::size_t i)
    {
      const Corner key{ around[i].prev, 0 };
      const Corner* it = std::lower_bound(around, around + count, key,
        [](const Corner& a, const Corner& b) { return a.next < b.next; });
      return it != around + count && it->next == around[i].prev
        ? static_cast<std::size_t>(it - around)
        : None;
    };

    // Walked corners are distinct (the successor map is one to one), so the count says
    // whether the fan is all of them; the bound only guards against a broken invariant.
    std::size_t walked = 1;
    bool closed = false;
    for (std::size_t i = 0; walked <= count;)
    {
      poll.tick();
      const std::size_t j = successor(i);
      if (j == None)
      {
        break;
      }
      if (j == 0)
      {
        closed = true;
        break;
      }
      ++walked;
      i = j;
    }
    if (!closed)
    {
      for (std::size_t i = 0; walked <= count;)
      {
        poll.tick();
        const std::size_t j = predecessor(i);
        if (j == None)
        {
          break;
        }
        ++walked;
        i = j;
      }
    }
    if (walked != count)
    {
      return false;
    }
  }
  return true;
}

} // namespace mlr::detail
