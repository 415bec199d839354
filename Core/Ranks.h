// A solve shared by several ranks: the rounds each phase runs in, the agreement between
// phases, the sums over ranks and the digest of what the ranks solve. Core has no MPI: the
// sums go through SolverOptions' hooks.
#pragma once

#include "Rgb.h"
#include "SolverOptions.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <type_traits>

namespace mlr
{

/**
 * Runs `phase` on this rank and, when options.ranks > 1, agrees with the other ranks on how
 * it went before any rank goes on (one sum over ranks): when any rank was cancelled or
 * failed, every rank throws, mlr::Cancelled or mlr::Error (its own exception on the rank
 * that threw, mlr::FailedOnAnotherRank elsewhere), so that no rank is left waiting in a
 * later sum. Every rank must call it at the same points. With one rank it only runs `phase`.
 * `secondsAgreeing`, when given, is increased by the time the agreement took (waiting for
 * the slowest rank included).
 */
void agreeAcrossRanks(const SolverOptions& options, const std::function<void()>& phase,
  double* secondsAgreeing = nullptr);

/**
 * Runs `tasks` tasks of one phase over this rank's workers. One rank runs them all in one
 * parallelFor. Several ranks cut the phase into rounds and rank r runs the tasks r, r + R,
 * r + 2R, ... of each: every task (path block or side block, keyed by its global index) runs
 * on exactly one rank, and interleaving spreads the dearer light positions over all ranks.
 * `fraction` gets this rank's share done, in [0, 1]; `secondsReducing` the agreements' time.
 */
void runOnRanks(std::size_t tasks, int workers, const SolverOptions& options,
  const std::function<void(std::size_t task, int worker)>& body,
  const std::function<bool(double fraction)>& fraction, double& secondsReducing);

/// Sums `count` integers over the ranks in place (SolverOptions::sumAcrossRanks); nothing on
/// one rank. `secondsReducing` gets the time it took.
void sumAcrossRanks(
  const SolverOptions& options, std::int64_t* values, std::size_t count, double& secondsReducing);

/// The same for counters.
void sumAcrossRanks(
  const SolverOptions& options, std::uint64_t* values, std::size_t count, double& secondsReducing);

/// Gives every rank the stored results that one rank filled, the others holding zeros: the
/// channels' codes are summed as doubles (so the sum is the one rank's code, bit for bit), a
/// block at a time so that no copy of the whole array is needed.
void sumStoredAcrossRanks(
  const SolverOptions& options, PackedRgb* values, std::size_t count, double& secondsReducing);

/// FNV-1a over the bytes of the values added.
struct Digest
{
  std::uint64_t value = 14695981039346656037ULL;
  template <typename T>
  void add(const T& v)
  {
    static_assert(std::is_arithmetic<T>::value, "a digest adds numbers, not their addresses");
    const unsigned char* bytes = reinterpret_cast<const unsigned char*>(&v);
    for (std::size_t i = 0; i < sizeof(T); ++i)
    {
      this->value = (this->value ^ bytes[i]) * 1099511628211ULL;
    }
  }
};

/// The digest of every option that decides the result (OptionRole::Result, from
/// visitSolverOptions), which ranks compare before they solve together.
std::uint64_t digestOf(const SolverOptions& options);

/**
 * The agreement of ranks that reduce with a maximum (as MPI's MAX_OP): whether any failed or
 * was cancelled, and whether their digests differ. A rank encodes its own outcome, the
 * communication takes the element-wise maximum over ranks, and every rank decodes the same
 * verdict.
 */
struct RankOutcome
{
  static constexpr std::size_t Size = 6;
  static void encode(bool failed, bool cancelled, std::uint64_t digest, long long (&values)[Size]);
  /// From the maxima over ranks of encode()'s values.
  static RankOutcome decode(const long long (&maxima)[Size]);

  bool failed = false;
  bool cancelled = false;
  bool digestsDiffer = false;
};

} // namespace mlr
