// The filter on ParaView's MPI engine: pvbatch --symmetric or pvserver under
// mpiexec. Every rank gathers the whole inputs, remeshes them alike and solves its share of
// the paths and gathering rays (Core sums the shares through the hooks set here); each rank
// then outputs the elements that come from its own input cells.
#pragma once

#include "Scene.h"
#include "Solver.h"

#include "vtkSmartPointer.h"
#include "vtkType.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

class vtkDataObject;
class vtkMultiProcessController;
class vtkPolyData;

namespace mlr::vtkparallel
{

/// The global controller when it has more than one process; null otherwise (serial runs,
/// pvpython, a one-rank pvbatch), where the filter behaves exactly as before.
vtkMultiProcessController* controller();

/**
 * Every rank's piece of one input, as one data object on every rank (a collective call).
 * Pieces equal byte for byte count once (the lowest rank's): an input that several ranks hold
 * whole, as the Light and Trajectory often are, is not joined with itself. When one rank
 * holds all the data (a reader or source that does not split), its piece is
 * returned as it is, so that the solve is the serial one bit for bit. Otherwise the pieces
 * are joined in a canonical cell order that does not depend on how the input was split: by
 * the global cell ids (vtkGlobalIds attribute, as RedistributeDataSet makes them) or else the
 * vtkOriginalCellIds array, or else by rank and then cell order; a cell present on several
 * ranks (ghost or duplicate, same id) is kept once, and points at equal coordinates are
 * merged. `cellRanks`, when given, receives the rank each cell of the result came from.
 * Throws mlr::Error when pieces disagree (a cell array on one rank's piece and not another's).
 */
vtkSmartPointer<vtkDataObject> gatherPieces(vtkMultiProcessController* controller,
  vtkDataObject* piece, const std::string& port, std::vector<int>* cellRanks = nullptr);

/**
 * Waits until every rank has come to this point, by point-to-point messages rather than a
 * collective, so that a rank that came alone (a script updating one rank only, or properties
 * set on some ranks only) is told which ranks it waits for instead of hanging in silence:
 * `report` gets that message after 10 s, then every minute. When `limitSeconds` > 0 and the
 * ranks are still missing after it, the message goes to `fail` and the MPI job is aborted
 * (MPI_Abort): giving up alone would leave this rank's message to be taken by the others'
 * next solve, which would then wait for this rank in a collective. Every rank must call it
 * as often as the others, as a collective; nothing is done without an MPI controller.
 */
void rendezvous(vtkMultiProcessController* controller, double limitSeconds,
  const std::function<void(const std::string&)>& report,
  const std::function<void(const std::string&)>& fail);

/// MLR_RANK_WAIT_LIMIT from the environment, in seconds (0, waiting without limit, when it
/// is unset or not a positive number).
double rankWaitLimit();

/// Sets options.rank, ranks and the sums over ranks (the controller's AllReduce).
void shareSolve(vtkMultiProcessController* controller, SolverOptions& options);

/// Frames of an animation held by a rank: a block of consecutive frames from `first`.
struct FrameBlock
{
  std::size_t first = 0;
  Solution frames;
};

/// What the ranks show of the frames that they hold apart.
struct RankFramesDisplay
{
  /// No frame, with every element's and patch's lit side, the animation's statistics and the
  /// error summary of every frame.
  Solution summary;
  /// The auto exposure of every frame (autoExposure).
  double exposure = 0;
  /// Whether each rank holds its own chunks' frames only (else every rank holds every frame).
  bool apart = false;
};

/**
 * The frames of an animation of `frames` frames streamed to this rank (Core's ranks take
 * whole chunks when there are at least as many as ranks; otherwise every rank gets every
 * frame). Chooses the lit side of every surface of `scene` over the whole animation, as
 * Solution::chooseLitSides does, and sets it in every block; gives every frame's error
 * figures and one auto exposure over every frame. With the frames apart, the elements' sums
 * go over the ranks (`options`' sums: a collective call) before they are pooled per
 * surface, so that every rank shows the same; the lit sides then match the serial choice
 * but for surfaces whose two sides' totals agree to the rounding of the sum.
 */
RankFramesDisplay combineRankFrames(const Scene& scene, std::vector<FrameBlock>& blocks,
  std::size_t frames, const Solution& statistics, const SolverOptions& options);

/// What the ranks agreed on: whether any failed or was cancelled, and the message to report
/// (this rank's own, or the first failed rank's, named).
struct Verdict
{
  bool failed = false;
  bool cancelled = false;
  std::string message;
};

/// A collective agreement: every rank calls it at the same point with its own outcome. When
/// none failed, `digest` (of what each rank is about to solve, digestOf(SolverOptions) among
/// it; 0 to skip) must be equal on every rank, or all fail: ranks that disagree would add up
/// two different solves. Core's RankOutcome decides; this only communicates.
Verdict agree(vtkMultiProcessController* controller, bool failed, bool cancelled,
  const std::string& message, std::uint64_t digest = 0);

/// FNV-1a over the bytes of the values added: Core's, which digests the solver options.
using Digest = mlr::Digest;

/**
 * The rank that owns each triangle (given by `triangles` on `points`): the rank of the input
 * cell of `scene` nearest its centroid, `cellRanks` giving each cell's rank. Every rank
 * computes the same, from the same gathered scene.
 */
std::vector<int> owners(vtkPolyData* scene, const std::vector<int>& cellRanks,
  const std::vector<Vec3>& points, const std::vector<Triangle>& triangles);

/// The cells of `full` whose owner is `rank` with the points they use and every point, cell
/// and field array (active attributes kept). Empty `cells` gives an empty mesh.
vtkSmartPointer<vtkPolyData> extractCells(vtkPolyData* full, const std::vector<vtkIdType>& cells);

} // namespace mlr::vtkparallel
