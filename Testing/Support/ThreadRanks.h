// Ranks as threads of one process, for Core's tests of solves shared by several ranks: Core
// knows no MPI, only SolverOptions' sum hooks, which a barrier serves here.
#pragma once

#include "SolverOptions.h"

#include <condition_variable>
#include <cstring>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

namespace mlr::checks
{

/// Sums over `ranks` threads: every call blocks until each rank has made its matching call.
class ThreadRanks
{
public:
  explicit ThreadRanks(int ranks)
    : Ranks(ranks)
  {
  }

  template <typename T>
  void sum(T* values, std::size_t count)
  {
    std::unique_lock<std::mutex> lock(this->Mutex);
    Round& round = this->Rounds[this->callIndex()];
    if (round.arrived == 0)
    {
      round.sum.assign(count * sizeof(T), 0);
    }
    T* total = reinterpret_cast<T*>(round.sum.data());
    for (std::size_t i = 0; i < count; ++i)
    {
      total[i] += values[i];
    }
    ++round.arrived;
    this->Changed.notify_all();
    this->Changed.wait(lock, [&] { return round.arrived == this->Ranks; });
    if (count > 0) // an empty sum (no overflow entries) may come with no array at all
    {
      std::memcpy(values, total, count * sizeof(T));
    }
    if (++round.left == this->Ranks)
    {
      this->Rounds.erase(this->callIndex());
    }
    ++this->Calls[std::this_thread::get_id()];
  }

  SolverOptions optionsFor(int rank, SolverOptions options)
  {
    options.rank = rank;
    options.ranks = this->Ranks;
    options.sumAcrossRanks = [this](std::int64_t* v, std::size_t n) { this->sum(v, n); };
    options.sumDoublesAcrossRanks = [this](double* v, std::size_t n) { this->sum(v, n); };
    return options;
  }

private:
  struct Round
  {
    std::vector<unsigned char> sum;
    int arrived = 0;
    int left = 0;
  };
  std::size_t callIndex() { return this->Calls[std::this_thread::get_id()]; }

  int Ranks;
  std::mutex Mutex;
  std::condition_variable Changed;
  std::map<std::size_t, Round> Rounds;
  std::map<std::thread::id, std::size_t> Calls;
};

} // namespace mlr::checks
