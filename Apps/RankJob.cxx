#include "RankJob.h"

#include <cstdlib>
#include <stdexcept>
#include <vector>

#ifdef MLR_CLI_MPI
#include "vtkMPIController.h"
#endif

namespace mlr::cli
{

namespace
{
/// The size of the job mpiexec started this process in: 1 when it was not started by one.
int launchedRanks()
{
  for (const char* name : { "OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE" })
  {
    if (const char* value = std::getenv(name))
    {
      const int size = std::atoi(value);
      if (size > 1)
      {
        return size;
      }
    }
  }
  return 1;
}
}

RankJob::RankJob(int* argc, char*** argv)
{
  if (launchedRanks() == 1)
  {
    return;
  }
#ifdef MLR_CLI_MPI
  this->Controller = vtkMPIController::New();
  this->Controller->Initialize(argc, argv);
  vtkMultiProcessController::SetGlobalController(this->Controller);
  this->Rank = this->Controller->GetLocalProcessId();
  this->Ranks = this->Controller->GetNumberOfProcesses();
#else
  (void)argc;
  (void)argv;
  throw std::runtime_error("mpiexec started several processes, but this build has no MPI "
                           "(VTK's ParallelMPI module): run one process, without mpiexec");
#endif
}

RankJob::~RankJob()
{
#ifdef MLR_CLI_MPI
  if (this->Controller)
  {
    vtkMultiProcessController::SetGlobalController(nullptr);
    this->Controller->Finalize();
    this->Controller->Delete();
  }
#endif
}

RankJob::Verdict RankJob::agree(bool failed, const std::string& message)
{
  Verdict verdict;
  verdict.failed = failed;
  verdict.message = failed ? message : std::string();
#ifdef MLR_CLI_MPI
  if (!this->Controller)
  {
    return verdict;
  }
  // Each rank's message length; then the messages of the ranks that failed.
  const vtkIdType length = failed ? static_cast<vtkIdType>(message.size()) + 1 : 0;
  std::vector<vtkIdType> lengths(static_cast<std::size_t>(this->Ranks));
  this->Controller->AllGather(&length, lengths.data(), 1);
  std::vector<vtkIdType> offsets(lengths.size(), 0);
  vtkIdType total = 0;
  for (std::size_t r = 0; r < lengths.size(); ++r)
  {
    offsets[r] = total;
    total += lengths[r];
  }
  if (total == 0)
  {
    return verdict;
  }
  std::vector<char> text(static_cast<std::size_t>(total));
  std::string sent = failed ? message : std::string();
  this->Controller->AllGatherV(sent.c_str(), text.data(), length, lengths.data(), offsets.data());
  verdict.failed = true;
  if (!failed)
  {
    for (std::size_t r = 0; r < lengths.size(); ++r)
    {
      if (lengths[r] > 0)
      {
        verdict.message = "rank " + std::to_string(r) + " of " + std::to_string(this->Ranks) +
          ": " + std::string(text.data() + offsets[r]);
        break;
      }
    }
  }
#endif
  return verdict;
}

RankJob::Holders RankJob::holders(bool holds)
{
  Holders result;
  result.count = holds ? 1 : 0;
  result.lowest = holds ? this->Rank : this->Ranks;
#ifdef MLR_CLI_MPI
  if (this->Controller)
  {
    int count = result.count, lowest = result.lowest;
    this->Controller->AllReduce(&count, &result.count, 1, vtkCommunicator::SUM_OP);
    this->Controller->AllReduce(&lowest, &result.lowest, 1, vtkCommunicator::MIN_OP);
  }
#endif
  return result;
}

long long RankJob::sum(long long value)
{
  long long total = value;
#ifdef MLR_CLI_MPI
  if (this->Controller)
  {
    this->Controller->AllReduce(&value, &total, 1, vtkCommunicator::SUM_OP);
  }
#endif
  return total;
}

void RankJob::sum(std::vector<double>& values)
{
#ifdef MLR_CLI_MPI
  if (this->Controller && !values.empty())
  {
    const std::vector<double> mine = values;
    this->Controller->AllReduce(
      mine.data(), values.data(), static_cast<vtkIdType>(values.size()), vtkCommunicator::SUM_OP);
  }
#else
  (void)values;
#endif
}

} // namespace mlr::cli
