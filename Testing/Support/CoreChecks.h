// Checks the Core test suites share: expected errors and the closed-enclosure energy balance.
#pragma once

#include "Error.h"
#include "Scene.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <string>

namespace mlr::checks
{

/// Runs `action`, expects mlr::Error, and checks that its message contains `words`.
template <typename Action>
void expectError(Action action, const std::string& words)
{
  try
  {
    action();
    ADD_FAILURE() << "no error; expected one mentioning \"" << words << "\"";
  }
  catch (const Error& e)
  {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << "message: " << e.what();
  }
}

/// Runs `action`, expects mlr::Error, and returns its message.
template <typename Action>
std::string errorOf(Action action)
{
  try
  {
    action();
  }
  catch (const Error& e)
  {
    return e.what();
  }
  ADD_FAILURE() << "no mlr::Error";
  return {};
}

/// The power balance of one frame, over both sides of every element.
struct Balance
{
  Rgb absorbed;     ///< sum_i A_i (1 - rho_i) / rho_i B_i: equals Phi in a closed enclosure
  Rgb radiantPower; ///< sum_i A_i B_i: Phi rho / (1 - rho) in one of uniform reflectance rho
};

inline Balance balanceOfFrame(const Scene& scene, const Solution& solution, std::size_t frame)
{
  Balance b;
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    const Rgb& rho = scene.elementReflectance(e);
    for (Side side : { Side::Front, Side::Back })
    {
      const Rgb B = solution.total(frame, e, side);
      for (int c = 0; c < 3; ++c)
      {
        b.absorbed[c] += scene.elementArea(e) * (1 - rho[c]) / rho[c] * B[c];
        b.radiantPower[c] += scene.elementArea(e) * B[c];
      }
    }
  }
  return b;
}

} // namespace mlr::checks
