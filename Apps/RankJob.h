// The command line under mpiexec: its processes solve one animation together (the filter
// shares the paths out over the ranks, or with chunks gives each rank whole chunks) and each
// writes the frames it holds. Every phase ends in an agreement, so that a failure on one rank
// stops them all at the same point instead of leaving the others waiting.
#pragma once

#include <string>
#include <vector>

class vtkMPIController;

namespace mlr::cli
{

class RankJob
{
public:
  /// Starts MPI when mpiexec started more than one process (Open MPI's or a PMI launcher's
  /// environment says so); otherwise the job is one rank and nothing is started. Throws
  /// std::runtime_error when several processes were started and this build has no MPI.
  RankJob(int* argc, char*** argv);
  ~RankJob();
  RankJob(const RankJob&) = delete;
  RankJob& operator=(const RankJob&) = delete;

  int rank() const { return this->Rank; }
  int ranks() const { return this->Ranks; }
  bool parallel() const { return this->Ranks > 1; }

  /// What the ranks agreed on: whether any failed, and the message to report (this rank's
  /// own, or the first failed rank's, named).
  struct Verdict
  {
    bool failed = false;
    std::string message;
  };
  /// Collective: every rank calls it at the same point with its own outcome.
  Verdict agree(bool failed, const std::string& message);

  /// Collective: how many ranks hold something (a frame), and the lowest that does (ranks()
  /// when none does).
  struct Holders
  {
    int count = 0;
    int lowest = 0;
  };
  Holders holders(bool holds);

  /// Collective: the sum of `value` over the ranks.
  long long sum(long long value);
  /// Collective: `values` summed over the ranks, in place.
  void sum(std::vector<double>& values);

private:
  vtkMPIController* Controller = nullptr;
  int Rank = 0;
  int Ranks = 1;
};

} // namespace mlr::cli
