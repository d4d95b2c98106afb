#pragma once
/// \file stage_clock.h
/// Seconds per stage of a pipeline, for its report.
#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace mrsnake {

/// Appends to `stages` the seconds of consecutive stages, each from the end of the one before
/// (or from construction, or the last restart()).
class StageClock {
 public:
  explicit StageClock(std::vector<std::pair<std::string, double>>& stages) : stages_(stages) {}
  void end(const std::string& name) {
    const auto now = std::chrono::steady_clock::now();
    stages_.emplace_back(name, std::chrono::duration<double>(now - start_).count());
    start_ = now;
  }
  void restart() { start_ = std::chrono::steady_clock::now(); }

 private:
  std::vector<std::pair<std::string, double>>& stages_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace mrsnake
