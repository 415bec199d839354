// Errors raised at Core's boundary. Every message names what to fix.
#pragma once

#include <stdexcept>
#include <string>

namespace mlr
{

/// Bad input or a failure that prevents a result (the message says what to fix).
class Error : public std::runtime_error
{
public:
  explicit Error(const std::string& message)
    : std::runtime_error(message)
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
