#include "MovingLightRadiosityParallel.h"

#include "Error.h"
#include "ErrorEstimate.h"
#include "MovingLightRadiosityDisplay.h"
#include "MovingLightRadiosityOutputs.h"
#include "Parallel.h"

#include "vtkCellData.h"
#include "vtkCharArray.h"
#include "vtkCommunicator.h"
#include "vtkDataSetAttributes.h"
#include "vtkFieldData.h"
#include "vtkIdList.h"
#include "vtkIdTypeArray.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"

#if VTK_MODULE_ENABLE_VTK_ParallelMPI
#include "vtkMPI.h"
#include "vtkMPICommunicator.h"
#include "vtkMPIController.h"
#endif

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <numeric>
#include <sstream>
#include <thread>
#include <tuple>

namespace mlr::vtkparallel
{

vtkMultiProcessController* controller()
{
  vtkMultiProcessController* c = vtkMultiProcessController::GetGlobalController();
  return c && c->GetNumberOfProcesses() > 1 ? c : nullptr;
}

namespace
{
bool isEmpty(vtkDataObject* data)
{
  return !data || data->GetNumberOfElements(vtkDataObject::POINT) == 0;
}

/// Cell ids that make the order canonical: the global ids, else vtkOriginalCellIds; null when
/// neither exists.
vtkDataArray* cellIdsOf(vtkPolyData* piece)
{
  vtkCellData* cd = piece->GetCellData();
  if (vtkDataArray* ids = cd->GetGlobalIds())
  {
    return ids;
  }
  vtkDataArray* ids = cd->GetArray("vtkOriginalCellIds");
  return ids && ids->GetNumberOfComponents() == 1 ? ids : nullptr;
}

/// A description of a piece's cell arrays, to check that pieces agree.
std::map<std::string, int> cellArraysOf(vtkPolyData* piece)
{
  std::map<std::string, int> arrays;
  vtkCellData* cd = piece->GetCellData();
  for (int i = 0; i < cd->GetNumberOfArrays(); ++i)
  {
    vtkAbstractArray* a = cd->GetAbstractArray(i);
    // Arrays the distribution itself adds (ids, ghosts) may differ between pieces.
    const std::string name = a && a->GetName() ? a->GetName() : "";
    if (!a || name.empty() || name.rfind("vtk", 0) == 0)
    {
      continue;
    }
    arrays[name] = a->GetNumberOfComponents();
  }
  return arrays;
}

/// Joins the non-empty polydata pieces in the canonical cell order (see gatherPieces).
vtkSmartPointer<vtkPolyData> joinPieces(const std::vector<vtkPolyData*>& pieces,
  const std::vector<int>& pieceRanks, const std::string& port, std::vector<int>* cellRanks)
{
  const std::map<std::string, int> expected = cellArraysOf(pieces.front());
  for (std::size_t p = 1; p < pieces.size(); ++p)
  {
    const std::map<std::string, int> found = cellArraysOf(pieces[p]);
    if (found != expected)
    {
      std::string difference;
      for (const auto& [name, components] : expected)
      {
        auto it = found.find(name);
        if (difference.empty() && (it == found.end() || it->second != components))
        {
          difference = "cell array '" + name + "' (" + std::to_string(components) +
            " components) is on rank " + std::to_string(pieceRanks.front()) +
            "'s piece but not on rank " + std::to_string(pieceRanks[p]) + "'s";
        }
      }
      for (const auto& [name, components] : found)
      {
        auto it = expected.find(name);
        if (difference.empty() && (it == expected.end() || it->second != components))
        {
          difference = "cell array '" + name + "' (" + std::to_string(components) +
            " components) is on rank " + std::to_string(pieceRanks[p]) +
            "'s piece but not on rank " + std::to_string(pieceRanks.front()) + "'s";
        }
      }
      throw Error("the " + port + " arrives in pieces over the ranks that disagree: the " +
        difference + ": give every piece the same cell arrays");
    }
  }

  // Every cell once, keyed by its global id when every piece has one, else by (rank, index).
  bool byIds = true;
  for (vtkPolyData* piece : pieces)
  {
    byIds = byIds && cellIdsOf(piece) != nullptr;
  }
  struct Cell
  {
    long long key;
    std::size_t piece;
    vtkIdType id;
  };
  std::vector<Cell> cells;
  for (std::size_t p = 0; p < pieces.size(); ++p)
  {
    vtkPolyData* piece = pieces[p];
    vtkDataArray* ids = byIds ? cellIdsOf(piece) : nullptr;
    vtkUnsignedCharArray* ghosts = piece->GetCellGhostArray();
    for (vtkIdType c = 0; c < piece->GetNumberOfCells(); ++c)
    {
      if (ghosts && (ghosts->GetValue(c) & vtkDataSetAttributes::DUPLICATECELL))
      {
        continue;
      }
      const long long key = ids ? static_cast<long long>(ids->GetComponent(c, 0))
                                : static_cast<long long>(cells.size());
      cells.push_back({ key, p, c });
    }
  }
  // Cells of one id on several ranks must be one cell (a ghost copy): ids that are only
  // local (0, 1, ... on every rank) name different cells, and then rank order is used.
  auto sameCell = [&](const Cell& a, const Cell& b)
  {
    vtkPolyData* pa = pieces[a.piece];
    vtkPolyData* pb = pieces[b.piece];
    if (a.piece == b.piece || pa->GetCellSize(a.id) != pb->GetCellSize(b.id))
    {
      return false;
    }
    vtkNew<vtkIdList> ia, ib;
    pa->GetCellPoints(a.id, ia);
    pb->GetCellPoints(b.id, ib);
    for (vtkIdType i = 0; i < ia->GetNumberOfIds(); ++i)
    {
      double xa[3], xb[3];
      pa->GetPoint(ia->GetId(i), xa);
      pb->GetPoint(ib->GetId(i), xb);
      if (xa[0] != xb[0] || xa[1] != xb[1] || xa[2] != xb[2])
      {
        return false;
      }
    }
    return true;
  };
  if (byIds)
  {
    std::vector<Cell> sorted = cells;
    std::stable_sort(
      sorted.begin(), sorted.end(), [](const Cell& a, const Cell& b) { return a.key < b.key; });
    bool global = true;
    for (std::size_t i = 1; i < sorted.size() && global; ++i)
    {
      global = sorted[i].key != sorted[i - 1].key || sameCell(sorted[i], sorted[i - 1]);
    }
    if (global)
    {
      sorted.erase(std::unique(sorted.begin(), sorted.end(),
                     [](const Cell& a, const Cell& b) { return a.key == b.key; }),
        sorted.end());
      cells = std::move(sorted);
    }
  }

  vtkNew<vtkPolyData> joined;
  vtkNew<vtkPoints> points;
  points->SetDataType(pieces.front()->GetPoints()->GetDataType());
  joined->SetPoints(points);
  joined->AllocateExact(
    static_cast<vtkIdType>(cells.size()), static_cast<vtkIdType>(cells.size()) * 4);
  joined->GetCellData()->CopyAllocate(
    pieces.front()->GetCellData(), static_cast<vtkIdType>(cells.size()));
  joined->GetPointData()->CopyAllocate(pieces.front()->GetPointData());
  joined->GetFieldData()->ShallowCopy(pieces.front()->GetFieldData());
  // Points at equal coordinates are one point, as they were before the split.
  std::map<std::array<double, 3>, vtkIdType> pointIds;
  std::vector<vtkIdType> ids;
  if (cellRanks)
  {
    cellRanks->clear();
  }
  for (const Cell& cell : cells)
  {
    vtkPolyData* piece = pieces[cell.piece];
    vtkIdType count = 0;
    const vtkIdType* from = nullptr;
    vtkNew<vtkIdList> scratch;
    piece->GetCellPoints(cell.id, count, from, scratch);
    ids.resize(static_cast<std::size_t>(count));
    for (vtkIdType i = 0; i < count; ++i)
    {
      std::array<double, 3> x;
      piece->GetPoint(from[i], x.data());
      auto [it, added] = pointIds.emplace(x, points->GetNumberOfPoints());
      if (added)
      {
        points->InsertNextPoint(x.data());
        joined->GetPointData()->CopyData(piece->GetPointData(), from[i], it->second);
      }
      ids[static_cast<std::size_t>(i)] = it->second;
    }
    const vtkIdType id = joined->InsertNextCell(piece->GetCellType(cell.id), count, ids.data());
    joined->GetCellData()->CopyData(piece->GetCellData(), cell.id, id);
    if (cellRanks)
    {
      cellRanks->push_back(pieceRanks[cell.piece]);
    }
  }
  joined->Squeeze();
  return joined;
}
}

vtkSmartPointer<vtkDataObject> gatherPieces(vtkMultiProcessController* controller,
  vtkDataObject* piece, const std::string& port, std::vector<int>* cellRanks)
{
  const int ranks = controller->GetNumberOfProcesses();
  // Each piece travels as bytes and every rank decodes every piece from the same bytes, its
  // own included: the ranks then hold identical inputs and remesh them identically.
  vtkNew<vtkCharArray> bytes;
  if (!isEmpty(piece) && !vtkCommunicator::MarshalDataObject(piece, bytes))
  {
    throw Error("the " + port + " piece of this rank could not be serialized for the other ranks");
  }
  const vtkIdType length = bytes->GetNumberOfValues();
  std::vector<vtkIdType> lengths(static_cast<std::size_t>(ranks), 0);
  std::vector<long long> sent{ static_cast<long long>(length) }, received(lengths.size());
  if (!controller->AllGather(sent.data(), received.data(), 1))
  {
    throw Error("gathering the " + port + " over the ranks failed");
  }
  std::vector<vtkIdType> offsets(lengths.size(), 0);
  vtkIdType total = 0;
  for (std::size_t r = 0; r < lengths.size(); ++r)
  {
    lengths[r] = static_cast<vtkIdType>(received[r]);
    offsets[r] = total;
    total += lengths[r];
  }
  std::vector<char> all(static_cast<std::size_t>(std::max<vtkIdType>(total, 1)));
  if (!controller->AllGatherV(length > 0 ? bytes->GetPointer(0) : all.data(), all.data(), length,
        lengths.data(), offsets.data()))
  {
    throw Error("gathering the " + port + " over the ranks failed");
  }
  std::vector<vtkSmartPointer<vtkDataObject>> pieces;
  std::vector<int> pieceRanks;
  int first = -1;
  for (int r = 0; r < ranks; ++r)
  {
    const std::size_t i = static_cast<std::size_t>(r);
    if (lengths[i] == 0)
    {
      continue;
    }
    if (first < 0)
    {
      first = r;
    }
    else if (lengths[i] == lengths[static_cast<std::size_t>(first)] &&
      std::equal(all.data() + offsets[i], all.data() + offsets[i] + lengths[i],
        all.data() + offsets[static_cast<std::size_t>(first)]))
    {
      // The same bytes as an earlier rank's: the input is whole on every rank that has it
      // (a source that ignores pieces, or one asked for the whole extent), not a piece.
      continue;
    }
    vtkNew<vtkCharArray> buffer;
    buffer->SetArray(
      all.data() + offsets[static_cast<std::size_t>(r)], lengths[static_cast<std::size_t>(r)], 1);
    vtkSmartPointer<vtkDataObject> decoded = vtkCommunicator::UnMarshalDataObject(buffer);
    if (!decoded)
    {
      throw Error(
        "the " + port + " piece of rank " + std::to_string(r) + " could not be read back");
    }
    pieces.push_back(decoded);
    pieceRanks.push_back(r);
  }
  if (pieces.empty())
  {
    if (cellRanks)
    {
      cellRanks->clear();
    }
    vtkSmartPointer<vtkDataObject> empty;
    empty.TakeReference(piece ? piece->NewInstance() : vtkPolyData::New());
    return empty;
  }
  if (pieces.size() == 1)
  {
    if (cellRanks)
    {
      cellRanks->assign(
        static_cast<std::size_t>(pieces.front()->GetNumberOfElements(vtkDataObject::CELL)),
        pieceRanks.front());
    }
    return pieces.front();
  }
  std::vector<vtkPolyData*> polyData;
  for (const auto& p : pieces)
  {
    vtkPolyData* pd = vtkPolyData::SafeDownCast(p);
    if (!pd)
    {
      throw Error("the " + port + " arrives in pieces over " + std::to_string(pieces.size()) +
        " ranks as a " + p->GetClassName() + ": give it whole on one rank, or as polydata");
    }
    polyData.push_back(pd);
  }
  return joinPieces(polyData, pieceRanks, port, cellRanks);
}

double rankWaitLimit()
{
  const char* text = std::getenv("MLR_RANK_WAIT_LIMIT");
  if (!text || !*text)
  {
    return 0;
  }
  char* end = nullptr;
  const double seconds = std::strtod(text, &end);
  return end && *end == '\0' && seconds > 0 ? seconds : 0;
}

void rendezvous(vtkMultiProcessController* controller, double limitSeconds,
  const std::function<void(const std::string&)>& report,
  const std::function<void(const std::string&)>& fail)
{
#if !VTK_MODULE_ENABLE_VTK_ParallelMPI
  (void)controller;
  (void)limitSeconds;
  (void)report;
  (void)fail;
#else
  vtkMPIController* mpi = vtkMPIController::SafeDownCast(controller);
  if (!mpi)
  {
    return;
  }
  // A tag of its own: VTK's and ParaView's messages (RMIs, data movers) never match it.
  constexpr int Tag = 31553;
  const int ranks = mpi->GetNumberOfProcesses();
  const int rank = mpi->GetLocalProcessId();
  int token = 1;
  std::vector<int> received(static_cast<std::size_t>(ranks), 0);
  std::vector<vtkMPICommunicator::Request> sends(received.size()), receives(received.size());
  std::vector<bool> arrived(received.size(), false);
  for (int q = 0; q < ranks; ++q)
  {
    if (q != rank)
    {
      const std::size_t i = static_cast<std::size_t>(q);
      mpi->NoBlockSend(&token, 1, q, Tag, sends[i]);
      mpi->NoBlockReceive(&received[i], 1, q, Tag, receives[i]);
    }
  }
  arrived[static_cast<std::size_t>(rank)] = true;
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  double nextReport = limitSeconds > 0 ? std::min(10.0, limitSeconds / 2) : 10.0;
  for (;;)
  {
    std::vector<int> missing;
    for (int q = 0; q < ranks; ++q)
    {
      const std::size_t i = static_cast<std::size_t>(q);
      if (!arrived[i] && receives[i].Test())
      {
        arrived[i] = true;
      }
      if (!arrived[i])
      {
        missing.push_back(q);
      }
    }
    if (missing.empty())
    {
      break;
    }
    const double waited = std::chrono::duration<double>(Clock::now() - start).count();
    const bool over = limitSeconds > 0 && waited >= limitSeconds;
    if (waited >= nextReport || over)
    {
      // The first few by number: on many ranks the list could run to thousands.
      constexpr std::size_t shown = 8;
      const std::size_t listed = missing.size() > shown ? shown : missing.size();
      std::string names;
      for (std::size_t k = 0; k < listed; ++k)
      {
        names += (k == 0                                           ? ""
                     : k + 1 == listed && listed == missing.size() ? " and "
                                                                   : ", ") +
          std::to_string(missing[k]);
      }
      if (listed < missing.size())
      {
        names += " and " + std::to_string(missing.size() - listed) + " more";
      }
      const std::string message = "rank " + std::to_string(rank) + " of " + std::to_string(ranks) +
        " has waited " + std::to_string(static_cast<long>(waited)) + " s for rank" +
        (missing.size() > 1 ? "s " : " ") + names +
        " to start the solve: every rank must update the filter together, with the same "
        "properties (a script that updates or sets properties on some ranks only leaves "
        "them waiting for each other for ever)";
      if (over)
      {
        std::ostringstream limit;
        limit << limitSeconds;
        const std::string final =
          message + "; MLR_RANK_WAIT_LIMIT is " + limit.str() + " s: aborting the MPI job";
        fail(final);
        // Also straight to stderr: an observer of the error (which keeps it from the output
        // window) has no time to show it before the job is killed.
        std::fprintf(stderr, "vtkMovingLightRadiosity: %s\n", final.c_str());
        std::fflush(stderr);
        vtkMPICommunicator* communicator = vtkMPICommunicator::SafeDownCast(mpi->GetCommunicator());
        MPI_Abort(communicator && communicator->GetMPIComm()
            ? *communicator->GetMPIComm()->GetHandle()
            : MPI_COMM_WORLD,
          1);
      }
      report(message);
      nextReport = waited + 60;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  // Every token was received, so the sends are complete or about to be.
  for (int q = 0; q < ranks; ++q)
  {
    if (q != rank)
    {
      sends[static_cast<std::size_t>(q)].Wait();
    }
  }
#endif
}

/// Sums go in chunks: MPI counts are ints.
constexpr std::size_t Chunk = std::size_t(1) << 24;

RankFramesDisplay combineRankFrames(const Scene& scene, std::vector<FrameBlock>& blocks,
  std::size_t frames, const Solution& statistics, const SolverOptions& options)
{
  RankFramesDisplay display;
  if (blocks.empty())
  {
    throw Error("internal error: no frame reached this rank");
  }
  std::size_t held = 0;
  for (const FrameBlock& b : blocks)
  {
    held += b.frames.frameCount();
  }
  display.apart = held < frames;
  const Solution& like = blocks.front().frames;
  const std::size_t elements = like.elementCount(), patches = like.patchCount();

  // The lit sides: each element's totals on both sides over every frame (and its
  // irradiance's), summed frame by frame as Solution::elementTotals does, over the ranks,
  // then pooled per surface by chooseLitSides.
  std::vector<double> sums(4 * elements, 0.0);
  for (const FrameBlock& b : blocks)
  {
    const Solution& s = b.frames;
    for (std::size_t e = 0; e < elements; ++e)
    {
      for (std::size_t f = 0; f < s.frameCount(); ++f)
      {
        sums[4 * e] += s.total(f, e, Side::Front).sum();
        sums[4 * e + 1] += s.total(f, e, Side::Back).sum();
        sums[4 * e + 2] += s.irradiance(f, e, Side::Front).sum();
        sums[4 * e + 3] += s.irradiance(f, e, Side::Back).sum();
      }
    }
  }
  if (display.apart)
  {
    options.sumDoublesAcrossRanks(sums.data(), sums.size());
  }
  Solution& summary = display.summary;
  summary = Solution(0, elements, patches);
  summary.chooseLitSides(
    scene,
    [&sums](std::size_t e) {
      return Solution::SideTotals{ sums[4 * e], sums[4 * e + 1], sums[4 * e + 2], sums[4 * e + 3] };
    },
    resolveThreadCount(options.threads));
  for (FrameBlock& b : blocks)
  {
    b.frames.litSideData() = summary.litSideData();
    b.frames.patchLitSideData() = summary.patchLitSideData();
  }

  // One exposure over every frame, from the histograms of the frames held.
  std::vector<std::uint64_t> histogram;
  for (const FrameBlock& b : blocks)
  {
    const std::vector<std::uint64_t> h = vtkoutputs::exposureHistogram(b.frames);
    histogram.resize(h.size(), 0);
    std::transform(h.begin(), h.end(), histogram.begin(), histogram.begin(), std::plus<>());
  }
  if (display.apart)
  {
    std::vector<std::int64_t> counts(histogram.begin(), histogram.end());
    options.sumAcrossRanks(counts.data(), counts.size());
    std::copy(counts.begin(), counts.end(), histogram.begin());
  }
  display.exposure = vtkoutputs::exposureOf(histogram);

  // Every frame's error figures, on the sides just chosen.
  summary.statistics = statistics.statistics;
  summary.errorEstimate = statistics.errorEstimate;
  if (like.hasErrorEstimate())
  {
    std::vector<double> figures(3 * frames, 0.0);
    for (const FrameBlock& b : blocks)
    {
      const Solution& s = b.frames;
      for (std::size_t f = 0; f < s.frameCount(); ++f)
      {
        const FrameError e = frameError(s, f,
          [&](std::size_t element, Side side) { return s.irradianceStdError(f, element, side); });
        const std::size_t i = 3 * (b.first + f);
        figures[i] = e.median;
        figures[i + 1] = e.p95;
        figures[i + 2] = static_cast<double>(e.litElements);
      }
    }
    if (display.apart)
    {
      options.sumDoublesAcrossRanks(figures.data(), figures.size());
    }
    ErrorEstimateSummary& errors = summary.errorEstimate;
    errors.relativeErrorMedian.assign(frames, 0.0);
    errors.relativeErrorP95.assign(frames, 0.0);
    errors.litElements.assign(frames, 0);
    for (std::size_t f = 0; f < frames; ++f)
    {
      errors.relativeErrorMedian[f] = figures[3 * f];
      errors.relativeErrorP95[f] = figures[3 * f + 1];
      errors.litElements[f] = static_cast<std::uint64_t>(figures[3 * f + 2]);
    }
  }
  return display;
}

void shareSolve(vtkMultiProcessController* controller, SolverOptions& options)
{
  options.rank = controller->GetLocalProcessId();
  options.ranks = controller->GetNumberOfProcesses();
  options.sumAcrossRanks = [controller](std::int64_t* values, std::size_t count)
  {
    std::vector<long long> send, receive;
    for (std::size_t first = 0; first < count; first += Chunk)
    {
      const std::size_t n = std::min(Chunk, count - first);
      send.assign(values + first, values + first + n);
      receive.resize(n);
      if (!controller->AllReduce(
            send.data(), receive.data(), static_cast<vtkIdType>(n), vtkCommunicator::SUM_OP))
      {
        throw Error("the sum over ranks failed");
      }
      std::copy(receive.begin(), receive.end(), values + first);
    }
  };
  options.sumDoublesAcrossRanks = [controller](double* values, std::size_t count)
  {
    std::vector<double> send;
    for (std::size_t first = 0; first < count; first += Chunk)
    {
      const std::size_t n = std::min(Chunk, count - first);
      send.assign(values + first, values + first + n);
      if (!controller->AllReduce(
            send.data(), values + first, static_cast<vtkIdType>(n), vtkCommunicator::SUM_OP))
      {
        throw Error("the sum over ranks failed");
      }
    }
  };
}

Verdict agree(vtkMultiProcessController* controller, bool failed, bool cancelled,
  const std::string& message, std::uint64_t digest)
{
  long long mine[RankOutcome::Size];
  RankOutcome::encode(failed, cancelled, digest, mine);
  long long all[RankOutcome::Size] = {};
  controller->AllReduce(mine, all, RankOutcome::Size, vtkCommunicator::MAX_OP);
  const RankOutcome outcome = RankOutcome::decode(all);
  Verdict verdict;
  verdict.failed = outcome.failed;
  verdict.cancelled = outcome.cancelled;
  if (!verdict.failed && !verdict.cancelled && outcome.digestsDiffer)
  {
    verdict.failed = true;
    verdict.message = "the ranks are not solving the same thing: their properties or inputs "
                      "differ (a rank updated alone, or a script set properties on one rank "
                      "only): give every rank the same properties and update them together";
    return verdict;
  }
  if (!verdict.failed)
  {
    return verdict;
  }
  // Every rank reports the failure; those that did not fail name the first rank that did.
  const std::string own = failed ? message : std::string();
  const int ranks = controller->GetNumberOfProcesses();
  const long long length = static_cast<long long>(own.size());
  std::vector<long long> lengths(static_cast<std::size_t>(ranks));
  controller->AllGather(&length, lengths.data(), 1);
  std::vector<vtkIdType> counts(lengths.begin(), lengths.end()), offsets(lengths.size(), 0);
  vtkIdType total = 0;
  for (std::size_t r = 0; r < counts.size(); ++r)
  {
    offsets[r] = total;
    total += counts[r];
  }
  std::vector<char> text(static_cast<std::size_t>(std::max<vtkIdType>(total, 1)));
  std::vector<char> sent(own.begin(), own.end());
  sent.push_back('\0');
  controller->AllGatherV(
    sent.data(), text.data(), static_cast<vtkIdType>(own.size()), counts.data(), offsets.data());
  if (failed)
  {
    verdict.message = message;
    return verdict;
  }
  for (int r = 0; r < ranks; ++r)
  {
    if (counts[static_cast<std::size_t>(r)] > 0)
    {
      verdict.message = "rank " + std::to_string(r) + " of " + std::to_string(ranks) + ": " +
        std::string(text.data() + offsets[static_cast<std::size_t>(r)],
          static_cast<std::size_t>(counts[static_cast<std::size_t>(r)]));
      break;
    }
  }
  if (verdict.message.empty())
  {
    verdict.message = "another rank failed";
  }
  return verdict;
}

std::vector<int> owners(vtkPolyData* scene, const std::vector<int>& cellRanks,
  const std::vector<Vec3>& points, const std::vector<Triangle>& triangles)
{
  std::vector<int> owner(triangles.size(), cellRanks.empty() ? 0 : cellRanks.front());
  if (cellRanks.empty() ||
    std::all_of(cellRanks.begin(), cellRanks.end(), [&](int r) { return r == cellRanks.front(); }))
  {
    return owner;
  }
  const std::vector<vtkIdType> nearest = mlr::vtkoutputs::nearestCells(scene, points, triangles);
  for (std::size_t t = 0; t < triangles.size(); ++t)
  {
    if (nearest[t] >= 0 && static_cast<std::size_t>(nearest[t]) < cellRanks.size())
    {
      owner[t] = cellRanks[static_cast<std::size_t>(nearest[t])];
    }
  }
  return owner;
}

vtkSmartPointer<vtkPolyData> extractCells(vtkPolyData* full, const std::vector<vtkIdType>& cells)
{
  vtkNew<vtkPolyData> out;
  vtkNew<vtkPoints> points;
  points->SetDataType(full->GetPoints() ? full->GetPoints()->GetDataType() : VTK_FLOAT);
  out->SetPoints(points);
  out->GetFieldData()->ShallowCopy(full->GetFieldData());
  out->GetPointData()->CopyAllocate(full->GetPointData());
  out->GetCellData()->CopyAllocate(full->GetCellData(), static_cast<vtkIdType>(cells.size()));
  out->AllocateExact(
    static_cast<vtkIdType>(cells.size()), static_cast<vtkIdType>(cells.size()) * 3);
  std::vector<vtkIdType> newId(static_cast<std::size_t>(full->GetNumberOfPoints()), -1);
  std::vector<vtkIdType> ids;
  vtkNew<vtkIdList> scratch;
  for (vtkIdType c : cells)
  {
    vtkIdType count = 0;
    const vtkIdType* from = nullptr;
    full->GetCellPoints(c, count, from, scratch);
    ids.resize(static_cast<std::size_t>(count));
    for (vtkIdType i = 0; i < count; ++i)
    {
      vtkIdType& id = newId[static_cast<std::size_t>(from[i])];
      if (id < 0)
      {
        id = points->InsertNextPoint(full->GetPoint(from[i]));
        out->GetPointData()->CopyData(full->GetPointData(), from[i], id);
      }
      ids[static_cast<std::size_t>(i)] = id;
    }
    const vtkIdType to = out->InsertNextCell(full->GetCellType(c), count, ids.data());
    out->GetCellData()->CopyData(full->GetCellData(), c, to);
  }
  out->Squeeze();
  return out;
}

} // namespace mlr::vtkparallel
