#include "Ranks.h"

#include "Error.h"
#include "Parallel.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <string>
#include <vector>

namespace mlr
{

namespace
{
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// A phase shared by several ranks runs in this many rounds, with an agreement between them:
/// a rank cancelled or failed stops the others within one round. Each agreement waits for
/// the slowest rank, so fewer rounds waste less (measured on 2 ranks: 32 rounds cost a
/// quarter of the solve on a busy machine).
constexpr std::size_t RoundsPerPhase = 8;
}

void agreeAcrossRanks(
  const SolverOptions& options, const std::function<void()>& phase, double* secondsAgreeing)
{
  if (options.ranks <= 1)
  {
    phase();
    return;
  }
  if (!options.sumAcrossRanks)
  {
    throw Error("a solve over several ranks needs SolverOptions::sumAcrossRanks");
  }
  std::exception_ptr failure;
  std::int64_t status[2] = { 0, 0 }; // ranks cancelled, ranks failed
  try
  {
    phase();
  }
  catch (const Cancelled&)
  {
    failure = std::current_exception();
    status[0] = 1;
  }
  catch (...)
  {
    failure = std::current_exception();
    status[1] = 1;
  }
  const auto start = Clock::now();
  options.sumAcrossRanks(status, 2);
  if (secondsAgreeing)
  {
    *secondsAgreeing += secondsSince(start);
  }
  if (failure)
  {
    std::rethrow_exception(failure);
  }
  if (status[1] > 0)
  {
    throw FailedOnAnotherRank("the solve failed on " + std::to_string(status[1]) + " other rank" +
      (status[1] > 1 ? "s" : "") + " of " + std::to_string(options.ranks));
  }
  if (status[0] > 0)
  {
    throw Cancelled();
  }
}

void runOnRanks(std::size_t tasks, int workers, const SolverOptions& options,
  const std::function<void(std::size_t task, int worker)>& body,
  const std::function<bool(double fraction)>& fraction, double& secondsReducing)
{
  const std::size_t ranks = static_cast<std::size_t>(options.ranks);
  const std::size_t rank = static_cast<std::size_t>(options.rank);
  if (ranks <= 1)
  {
    parallelFor(tasks, workers, body,
      [&](std::size_t done)
      {
        return fraction(
          static_cast<double>(done) / static_cast<double>(std::max<std::size_t>(tasks, 1)));
      });
    return;
  }
  const std::size_t rounds = std::min(RoundsPerPhase, std::max<std::size_t>(tasks, 1));
  auto mineOf = [&](std::size_t length)
  { return length > rank ? (length - rank + ranks - 1) / ranks : 0; };
  std::size_t mineTotal = 0;
  for (std::size_t q = 0; q < rounds; ++q)
  {
    mineTotal += mineOf(tasks * (q + 1) / rounds - tasks * q / rounds);
  }
  std::size_t doneBefore = 0;
  for (std::size_t q = 0; q < rounds; ++q)
  {
    const std::size_t begin = tasks * q / rounds;
    const std::size_t mine = mineOf(tasks * (q + 1) / rounds - begin);
    agreeAcrossRanks(
      options,
      [&]
      {
        parallelFor(
          mine, workers,
          [&](std::size_t task, int worker) { body(begin + rank + task * ranks, worker); },
          [&](std::size_t done)
          {
            return fraction(static_cast<double>(doneBefore + done) /
              static_cast<double>(std::max<std::size_t>(mineTotal, 1)));
          });
      },
      &secondsReducing);
    doneBefore += mine;
  }
}

void sumAcrossRanks(
  const SolverOptions& options, std::int64_t* values, std::size_t count, double& secondsReducing)
{
  if (options.ranks <= 1)
  {
    return;
  }
  const auto start = Clock::now();
  options.sumAcrossRanks(values, count);
  secondsReducing += secondsSince(start);
}

void sumAcrossRanks(
  const SolverOptions& options, std::uint64_t* values, std::size_t count, double& secondsReducing)
{
  if (options.ranks <= 1)
  {
    return;
  }
  std::vector<std::int64_t> signedValues(values, values + count);
  sumAcrossRanks(options, signedValues.data(), count, secondsReducing);
  std::transform(signedValues.begin(), signedValues.end(), values,
    [](std::int64_t v) { return static_cast<std::uint64_t>(v); });
}

void sumStoredAcrossRanks(
  const SolverOptions& options, PackedRgb* values, std::size_t count, double& secondsReducing)
{
  if (options.ranks <= 1)
  {
    return;
  }
  const auto start = Clock::now();
  constexpr std::size_t block = std::size_t(1) << 18;
  std::vector<double> buffer(3 * std::min(count, block));
  for (std::size_t first = 0; first < count; first += block)
  {
    const std::size_t n = std::min(block, count - first);
    for (std::size_t i = 0; i < n; ++i)
    {
      const PackedRgb& c = values[first + i];
      buffer[3 * i] = c.r;
      buffer[3 * i + 1] = c.g;
      buffer[3 * i + 2] = c.b;
    }
    options.sumDoublesAcrossRanks(buffer.data(), 3 * n);
    for (std::size_t i = 0; i < n; ++i)
    {
      // Only what changed is written: the runs no rank wrote (the sides light cannot reach)
      // stay pages never written, which take no memory (MemoryPlan).
      PackedRgb& c = values[first + i];
      const auto r = static_cast<std::uint16_t>(buffer[3 * i]);
      const auto g = static_cast<std::uint16_t>(buffer[3 * i + 1]);
      const auto b = static_cast<std::uint16_t>(buffer[3 * i + 2]);
      if (c.r != r || c.g != g || c.b != b)
      {
        c.r = r;
        c.g = g;
        c.b = b;
      }
    }
  }
  secondsReducing += secondsSince(start);
}

std::uint64_t digestOf(const SolverOptions& options)
{
  Digest digest;
  visitSolverOptions(options,
    [&](const char*, const auto& value, OptionRole role)
    {
      using T = std::decay_t<decltype(value)>;
      if constexpr (std::is_arithmetic<T>::value)
      {
        if (role == OptionRole::Result)
        {
          digest.add(value);
        }
      }
    });
  return digest.value;
}

void RankOutcome::encode(
  bool failed, bool cancelled, std::uint64_t digest, long long (&values)[Size])
{
  // The digest as its low and high halves, and negated, so that one maximum gives both the
  // largest and the smallest digest: they are equal when every rank's is.
  const long long low = static_cast<long long>(digest & 0xffffffffULL);
  const long long high = static_cast<long long>(digest >> 32);
  const long long mine[Size] = { failed ? 1 : 0, cancelled ? 1 : 0, low, high, -low, -high };
  std::copy(mine, mine + Size, values);
}

RankOutcome RankOutcome::decode(const long long (&maxima)[Size])
{
  RankOutcome outcome;
  outcome.failed = maxima[0] != 0;
  outcome.cancelled = maxima[1] != 0;
  outcome.digestsDiffer = maxima[2] != -maxima[4] || maxima[3] != -maxima[5];
  return outcome;
}

} // namespace mlr
