#include "ProgressBar.h"

#include <algorithm>
#include <cstdio>
#include <unistd.h>

namespace mlr::cli
{

namespace
{
constexpr int BarWidth = 30;
}

ProgressBar::ProgressBar()
  : Enabled(isatty(fileno(stdout)) != 0)
{
}

ProgressBar::~ProgressBar()
{
  this->finish();
}

void ProgressBar::show(double fraction, const std::string& label)
{
  if (!this->Enabled)
  {
    return;
  }
  const int percent = static_cast<int>(100.0 * std::clamp(fraction, 0.0, 1.0));
  const auto now = std::chrono::steady_clock::now();
  // Redraw on a new percent or label, at most 20 times a second.
  if ((percent == this->LastPercent && label == this->LastLabel) ||
    (this->Drawn && label == this->LastLabel &&
      now - this->LastDraw < std::chrono::milliseconds(50)))
  {
    return;
  }
  const int filled = percent * BarWidth / 100;
  std::string line = "\r" + std::string(percent < 10 ? "  " : (percent < 100 ? " " : "")) +
    std::to_string(percent) + "% [" + std::string(static_cast<std::size_t>(filled), '#') +
    std::string(static_cast<std::size_t>(BarWidth - filled), '-') + "] " + label;
  const std::size_t width = line.size();
  line.append(this->LastWidth > width ? this->LastWidth - width : 0, ' ');
  std::fputs(line.c_str(), stdout);
  std::fflush(stdout);
  this->Drawn = true;
  this->LastPercent = percent;
  this->LastLabel = label;
  this->LastWidth = width;
  this->LastDraw = now;
}

void ProgressBar::finish()
{
  if (this->Enabled && this->Drawn)
  {
    std::fputs(("\r" + std::string(this->LastWidth, ' ') + "\r").c_str(), stdout);
    std::fflush(stdout);
    this->Drawn = false;
    this->LastPercent = -1;
    this->LastWidth = 0;
  }
}

} // namespace mlr::cli
