// A one-line progress bar for terminals.
#pragma once

#include <chrono>
#include <string>

namespace mlr::cli
{

/// Draws "  42% [########------------] label" on stdout, redrawn in place, and only when
/// stdout is a terminal: logs and pipes get no control characters.
class ProgressBar
{
public:
  ProgressBar();
  ~ProgressBar();

  void show(double fraction, const std::string& label);
  /// Erases the bar, so that what follows starts on a clean line.
  void finish();

private:
  bool Enabled;
  bool Drawn = false;
  int LastPercent = -1;
  std::string LastLabel;
  std::size_t LastWidth = 0;
  std::chrono::steady_clock::time_point LastDraw;
};

} // namespace mlr::cli
