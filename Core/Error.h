// Errors raised at Core's boundary. Every message names what to fix.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace mlr
{

/// `value` as messages show it: the shortest of fixed and scientific, without trailing zeros
/// (std::to_string gives "0.000000").
inline std::string formatNumber(double value)
{
  std::ostringstream s;
  s << value;
  return s.str();
}

/// Bad input or a failure that prevents a result (the message says what to fix).
class Error : public std::runtime_error
{
public:
  explicit Error(const std::string& message)
    : std::runtime_error(message)
  {
  }
};

/// A solve shared by several ranks stopped because another rank failed (its error is the
/// one to report; SolverOptions::ranks).
class FailedOnAnotherRank : public Error
{
public:
  explicit FailedOnAnotherRank(const std::string& message)
    : Error(message)
  {
  }
};

/// The caller cancelled through the progress callback: no result exists.
class Cancelled : public Error
{
public:
  Cancelled()
    : Error("cancelled before completion: no result was produced")
  {
  }
};

} // namespace mlr
