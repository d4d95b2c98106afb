#pragma once
/// \file progress.h
/// Long algorithms report progress through this callback; the command line draws it.
#include <functional>
#include <string>

namespace mrsnake {

/// Called with a stage name and the fraction done in [0, 1]. May be empty.
using ProgressFn = std::function<void(const std::string& stage, double fraction)>;

inline void report(const ProgressFn& progress, const std::string& stage, double fraction) {
  if (progress) progress(stage, fraction);
}

}  // namespace mrsnake
