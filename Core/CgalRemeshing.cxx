// Isotropic remeshing with CGAL, region by region, after the soup is repaired and split
// along its contact lines; what CGAL refuses is only refined.
#include "CgalRemeshingInternal.h"

#include "Error.h"
#include "Plural.h"

#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/boost/graph/helpers.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <new>
#include <sstream>

namespace mlr::detail
{
using namespace cgal;

namespace
{

/// Remeshing passes and tangential relaxation steps per pass. The first pass does most of
/// the splitting or coarsening, the others even out valences and angles. Measured on cubes,
/// rooms and spheres: 5 x 5 keeps the smallest angles near 25-40 degrees at little cost.
constexpr unsigned Iterations = 5;
constexpr unsigned RelaxationSteps = 5;
/// Warnings about refused regions beyond this many are summed up in one line.
constexpr std::size_t MaximumRegionWarnings = 10;

/// What a remeshing outcome is short of to be kept; empty when it is fine.
using Refusal = std::string;

std::string describe(const Rgb& c)
{
  std::ostringstream s;
  s << "(" << c.r << ", " << c.g << ", " << c.b << ")";
  return s.str();
}

std::string describeRegion(const Region& region, const std::vector<Material>& materials)
{
  std::ostringstream s;
  s << "region " << region.id << " (reflectance "
    << describe(materials[region.material].reflectance) << ", "
    << countOf(region.triangles.size(), "input triangle") << ")";
  return s.str();
}

void checkProgress(const std::function<bool(double)>& progress, double fraction)
{
  if (progress && !progress(fraction))
  {
    throw Cancelled();
  }
}

/**
 * Projects moved vertices onto the input triangles of their own region, as CGAL does by
 * default, but onto the input as it was before the first pass: remeshing runs one pass per
 * call (to check for cancellation between passes) and CGAL would otherwise project onto the
 * previous pass's output, drifting off curved input.
 */
class RegionProjection
{
public:
  RegionProjection(const Mesh& mesh, const Mesh::Property_map<FaceIndex, std::size_t>& region,
    std::size_t regionCount)
    : MeshRef(&mesh)
    , RegionMap(region)
    , Triangles(std::make_shared<std::vector<TriangleList>>(regionCount))
    , Trees(std::make_shared<std::vector<std::unique_ptr<Tree>>>())
  {
    for (FaceIndex f : mesh.faces())
    {
      const HalfedgeIndex h = mesh.halfedge(f);
      (*this->Triangles)[region[f]].emplace_back(mesh.point(mesh.source(h)),
        mesh.point(mesh.target(h)), mesh.point(mesh.target(mesh.next(h))));
    }
    for (const TriangleList& triangles : *this->Triangles)
    {
      this->Trees->push_back(std::make_unique<Tree>(triangles.begin(), triangles.end()));
      this->Trees->back()->accelerate_distance_queries();
    }
  }

  Point operator()(VertexIndex v) const
  {
    const Mesh& mesh = *this->MeshRef;
    HalfedgeIndex h = mesh.halfedge(v);
    if (mesh.is_border(h))
    {
      h = mesh.opposite(h);
    }
    const FaceIndex f = mesh.face(h);
    if (f == Mesh::null_face())
    {
      return mesh.point(v);
    }
    return (*this->Trees)[this->RegionMap[f]]->closest_point(mesh.point(v));
  }

private:
  const Mesh* MeshRef;
  Mesh::Property_map<FaceIndex, std::size_t> RegionMap;
  // Shared: CGAL copies the functor.
  std::shared_ptr<std::vector<TriangleList>> Triangles;
  std::shared_ptr<std::vector<std::unique_ptr<Tree>>> Trees;
};

/// One remeshing pass over the whole component; passes run one by one so that progress can
/// be reported and cancellation checked between them.
void remeshPass(Mesh& mesh, ComponentLayout& layout, double h, const RegionProjection& projection,
  CancellationPoll& poll)
{
  PMP::isotropic_remeshing(mesh.faces(), h, mesh,
    CGAL::parameters::number_of_iterations(1)
      .vertex_point_map(PolledPointMap{ &mesh, &poll })
      .face_patch_map(layout.region)
      .edge_is_constrained_map(layout.constrained)
      .vertex_is_constrained_map(layout.corner)
      .protect_constraints(false)
      .collapse_constraints(true)
      .relax_constraints(false)
      .number_of_relaxation_steps(RelaxationSteps)
      .projection_functor(projection));
}

/// Why each region's remeshed faces cannot be kept (empty when they can).
std::vector<Refusal> checkRegions(const Mesh& mesh, const ComponentLayout& layout, double tolerance)
{
  std::vector<double> area(layout.regions.size(), 0.0);
  std::vector<Refusal> refusals(layout.regions.size());
  for (FaceIndex f : mesh.faces())
  {
    const std::size_t r = layout.region[f];
    if (r >= layout.regions.size())
    {
      continue; // cannot happen: CGAL gives new faces their parent's patch
    }
    const HalfedgeIndex h = mesh.halfedge(f);
    const Point& a = mesh.point(mesh.source(h));
    const Point& b = mesh.point(mesh.target(h));
    const Point& c = mesh.point(mesh.target(mesh.next(h)));
    const double faceArea = triangleArea(a, b, c);
    if (!(faceArea > 0) || !std::isfinite(faceArea))
    {
      refusals[r] = "remeshing left a degenerate triangle";
    }
    area[r] += faceArea;
  }
  for (std::size_t r = 0; r < layout.regions.size(); ++r)
  {
    const double input = layout.regions[r].inputArea;
    const double change = (area[r] - input) / input;
    if (refusals[r].empty() && !(std::abs(change) <= tolerance))
    {
      std::ostringstream s;
      s << "remeshing changed its area by " << 100 * change << "% (more than " << 100 * tolerance
        << "%; the patch size may be too large for its curvature)";
      refusals[r] = s.str();
    }
  }
  return refusals;
}

/// Appends the faces of the accepted regions, oriented like their input polygons.
void emitRegions(const Mesh& mesh, const ComponentLayout& layout,
  const std::vector<Refusal>& refusals, CgalRemeshOutput& out)
{
  constexpr std::uint32_t None = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> outputIndex(mesh.num_vertices(), None); // removed ones too
  for (FaceIndex f : mesh.faces())
  {
    const std::size_t r = layout.region[f];
    if (r >= layout.regions.size() || !refusals[r].empty())
    {
      continue;
    }
    Triangle t{};
    int k = 0;
    for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
    {
      std::uint32_t& index = outputIndex[v];
      if (index == None)
      {
        index = static_cast<std::uint32_t>(out.points.size());
        out.points.push_back(toVec3(mesh.point(v)));
      }
      t[static_cast<std::size_t>(k++)] = index;
    }
    if (layout.regions[r].flipped)
    {
      std::swap(t[1], t[2]);
    }
    out.triangles.push_back(t);
    out.material.push_back(layout.regions[r].material);
  }
}

/// Collects the refused regions' triangles, oriented like their input, and says why, up to a
/// few warnings.
void refuseRegion(const Region& region, const RepairedSoup& soup, const TriangleSoup& input,
  const std::string& why, const std::vector<Material>& materials, CgalRemeshOutput& out)
{
  ++out.fallbackRegions;
  for (std::size_t s : region.triangles)
  {
    CgalTriangle t = soup.triangles[s];
    if (soup.flipped[s])
    {
      std::swap(t[1], t[2]);
    }
    const auto first = static_cast<std::uint32_t>(out.refinePoints.size());
    for (std::size_t k : t)
    {
      out.refinePoints.push_back(toVec3(soup.points[k]));
    }
    out.refineOnly.triangles.push_back({ first, first + 1, first + 2 });
    out.refineOnly.material.push_back(input.material[soup.input[s]]);
  }
  if (out.fallbackRegions <= MaximumRegionWarnings)
  {
    out.warnings.push_back(
      describeRegion(region, materials) + " was only refined, not remeshed: " + why);
  }
}

/**
 * Runs `step`, which calls CGAL. Any exception becomes the reason to refuse the component
 * (CGAL reports failed preconditions as exceptions, or not at all with CGAL_NDEBUG), except
 * running out of memory, which no fallback would survive.
 */
template <typename Step>
bool guarded(const Step& step, std::string& failure)
{
  try
  {
    step();
    return true;
  }
  catch (const Cancelled&)
  {
    throw; // the caller asked to stop: not a CGAL failure
  }
  catch (const std::bad_alloc&)
  {
    throw Error("ran out of memory while remeshing: give a larger patch size or a smaller scene");
  }
  catch (const std::exception& e)
  {
    failure = std::string("CGAL failed (") + e.what() + ")";
    return false;
  }
}

/// Refuses a component whose regions are not known yet, as one region.
void refuseComponent(const RepairedSoup& soup, const TriangleSoup& input,
  const std::vector<Material>& materials, const std::vector<std::size_t>& faces,
  const std::string& why, CgalRemeshOutput& out)
{
  Region whole;
  whole.id = out.regions++;
  whole.material = input.material[soup.input[faces.front()]];
  whole.triangles = faces;
  refuseRegion(whole, soup, input, why, materials, out);
}

/// Remeshes one component; what CGAL refuses goes to out.refineOnly with a warning.
/// `afterPass` reports progress outside the guarded CGAL calls, so cancelling is never
/// mistaken for a failure.
void processComponent(const RepairedSoup& soup, const TriangleSoup& input,
  const std::vector<Material>& materials, const std::vector<std::size_t>& faces,
  const CgalRemeshSettings& settings, std::vector<std::size_t>& localIndex,
  const std::function<void(double)>& afterPass, CancellationPoll& poll, CgalRemeshOutput& out)
{
  Mesh mesh;
  ComponentLayout layout;
  std::vector<std::size_t> pointOfVertex;
  bool valid = false;
  std::string failure;
  const bool built = guarded(
    [&]
    {
      mesh = buildComponentMesh(soup, faces, localIndex, pointOfVertex, poll);
      valid = CGAL::is_valid_polygon_mesh(mesh) && CGAL::is_triangle_mesh(mesh);
    },
    failure);
  if (built && !valid)
  {
    failure = "its surface is not a valid triangle mesh after repair";
  }
  poll.check();
  if (!built || !valid ||
    !guarded(
      [&]
      {
        layout = layOutComponent(
          mesh, soup, input, faces, pointOfVertex, settings.sharpEdgeAngle, out.regions);
      },
      failure))
  {
    refuseComponent(soup, input, materials, faces, failure, out);
    return;
  }
  out.regions += layout.regions.size();

  poll.check();
  std::unique_ptr<RegionProjection> projection;
  bool ok = guarded(
    [&] {
      projection = std::make_unique<RegionProjection>(mesh, layout.region, layout.regions.size());
    },
    failure);
  for (unsigned pass = 0; ok && pass < Iterations; ++pass)
  {
    poll.check();
    ok = guarded(
      [&] { remeshPass(mesh, layout, settings.targetEdgeLength, *projection, poll); }, failure);
    afterPass(double(pass + 1) / Iterations);
  }
  poll.check();
  std::vector<Refusal> refusals(layout.regions.size(), failure);
  if (ok &&
    guarded([&] { refusals = checkRegions(mesh, layout, settings.areaTolerance); }, failure))
  {
    emitRegions(mesh, layout, refusals, out);
  }
  else
  {
    refusals.assign(layout.regions.size(), failure);
  }
  for (std::size_t r = 0; r < layout.regions.size(); ++r)
  {
    if (!refusals[r].empty())
    {
      refuseRegion(layout.regions[r], soup, input, refusals[r], materials, out);
    }
  }
}

void addRepairWarnings(CgalRemeshOutput& out)
{
  if (out.degenerateTriangles > 0)
  {
    out.warnings.push_back("removed " + countOf(out.degenerateTriangles, "triangle") +
      " that became degenerate when duplicate points were merged");
  }
  if (out.duplicateTriangles > 0)
  {
    out.warnings.push_back("removed " + countOf(out.duplicateTriangles, "duplicate triangle") +
      " (on the same 3 points as an earlier one, whose material was kept)");
  }
  if (out.foldedTriangles > 0)
  {
    out.warnings.push_back("removed " + countOf(out.foldedTriangles, "triangle") +
      " overlapping a larger polygon in its plane, facing the same way (two triangulations of "
      "one face, a polygon drawn over another, a block's face on a wall; the larger was kept)");
  }
  if (out.splitPoints > 0)
  {
    out.warnings.push_back("split " + countOf(out.splitPoints, "point") +
      " where the surface is not a manifold (an edge shared by more than two faces, "
      "faces meeting only at a point, or opposite orientations): the surfaces meeting there "
      "were remeshed separately");
  }
  if (out.fallbackRegions > MaximumRegionWarnings)
  {
    out.warnings.push_back("... and " +
      countOf(out.fallbackRegions - MaximumRegionWarnings, "more region") +
      " only refined, not remeshed");
  }
}
} // namespace

CgalRemeshOutput remeshWithCgal(const std::vector<Vec3>& points, const TriangleSoup& input,
  const std::vector<Material>& materials, const CgalRemeshSettings& settings,
  const std::function<bool(double)>& progress)
{
  CgalRemeshOutput out;
  RepairedSoup soup;
  std::vector<std::vector<std::size_t>> components;
  constexpr double RepairShare = 0.05;
  constexpr double SplitShare = 0.05;
  double reported = 0;
  CancellationPoll poll([&] { return !progress || progress(reported); });
  try
  {
    soup = repairAndOrient(points, input, out, poll);
    poll.check();
    components = connectedComponents(soup, poll);
  }
  catch (const Cancelled&)
  {
    throw;
  }
  catch (const std::bad_alloc&)
  {
    throw Error("ran out of memory while repairing the surface: give a smaller scene");
  }
  catch (const std::exception& e)
  {
    out = CgalRemeshOutput{};
    out.refinePoints = points;
    out.refineOnly = input;
    out.warnings.push_back(std::string("CGAL could not repair the surface (") + e.what() +
      "): all " + countOf(input.triangles.size(), "triangle") + " were only refined, not remeshed");
    return out;
  }
  reported = RepairShare;
  checkProgress(progress, reported);

  if (settings.splitAtContacts)
  {
    RepairedSoup split = soup;
    CgalRemeshOutput counts;
    std::string failure;
    bool ok = false;
    bool changed = false;
    const auto start = std::chrono::steady_clock::now();
    try
    {
      ok = guarded([&] { changed = splitAtContacts(split, settings, counts, poll); }, failure);
    }
    catch (const OverLimit& e)
    {
      throw Error(e.message);
    }
    std::vector<std::vector<std::size_t>> splitComponents;
    ok = ok &&
      (!changed || guarded([&] { splitComponents = connectedComponents(split, poll); }, failure));
    out.contactSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (ok && changed)
    {
      soup = std::move(split);
      components = std::move(splitComponents);
      out.contactSplitTriangles = counts.contactSplitTriangles;
      out.contactEdges = counts.contactEdges;
      out.coveredTriangles = counts.coveredTriangles;
      out.coveredArea = counts.coveredArea;
      out.splitPoints += counts.splitPoints;
    }
    else if (!ok)
    {
      out.warnings.push_back("surfaces were not split where they touch or cross (" + failure +
        "): patches may straddle contact lines, where light and shadow then leak");
    }
  }
  reported = RepairShare + SplitShare;
  checkProgress(progress, reported);

  // Progress in proportion to the faces remeshed, checked after every pass, in steps of at
  // least 0.1% so that thousands of tiny components do not flood the caller.
  const double total = static_cast<double>(std::max<std::size_t>(1, soup.triangles.size()));
  double done = 0;
  auto report = [&](double componentFraction)
  {
    const double fraction =
      RepairShare + SplitShare + (1 - RepairShare - SplitShare) * componentFraction;
    if (fraction - reported >= 0.001)
    {
      reported = fraction;
      checkProgress(progress, fraction);
    }
  };
  std::vector<std::size_t> localIndex(soup.points.size(), std::numeric_limits<std::size_t>::max());
  for (const std::vector<std::size_t>& faces : components)
  {
    const double share = static_cast<double>(faces.size()) / total;
    auto afterPass = [&](double passFraction) { report(done + share * passFraction); };
    processComponent(soup, input, materials, faces, settings, localIndex, afterPass, poll, out);
    done += share;
  }
  addRepairWarnings(out);
  return out;
}

} // namespace mlr::detail
