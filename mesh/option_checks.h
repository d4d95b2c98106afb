#pragma once
/// \file option_checks.h
/// Range checks of options, named by their options-file keys ("snake.max_iterations"), so
/// that a bad value is refused before any work with a message that says which key and what
/// it may be, instead of a crash, a hang or a silently different run.
#include <cmath>
#include <sstream>
#include <string>

#include "mesh/errors.h"

namespace mrsnake {

/// \throw OptionsError "the option KEY must be RANGE" unless ok.
inline void require(bool ok, const std::string& key, const std::string& range) {
  if (!ok) throw OptionsError("the option " + key + " must be " + range);
}

/// \throw OptionsError naming `key` unless lo <= value <= hi (a NaN is outside every range).
template <class T>
void require_in(const std::string& key, T value, T lo, T hi) {
  if (value >= lo && value <= hi) return;
  std::ostringstream s;
  s << "the option " << key << " is " << value << "; it must be in [" << lo << ", " << hi << "]";
  throw OptionsError(s.str());
}

/// \throw OptionsError naming `key` unless value >= lo.
template <class T>
void require_at_least(const std::string& key, T value, T lo) {
  if (value >= lo) return;
  std::ostringstream s;
  s << "the option " << key << " is " << value << "; it must be at least " << lo;
  throw OptionsError(s.str());
}

/// \throw OptionsError naming `key` unless value > 0 and finite.
inline void require_positive(const std::string& key, double value) {
  if (value > 0 && std::isfinite(value)) return;
  std::ostringstream s;
  s << "the option " << key << " is " << value << "; it must be a positive number";
  throw OptionsError(s.str());
}

}  // namespace mrsnake
