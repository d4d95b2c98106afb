#pragma once
/// \file option_checks.h
/// Range checks of options, named by their options-file keys ("snake.max_iterations"), so
/// that a bad value is refused before any work, with a message naming the key and its range.
#include <cmath>
#include <sstream>
#include <string>

#include "mesh/errors.h"

namespace mrsnake {

namespace option_checks_detail {
template <class T>
std::string text(T value) {
  std::ostringstream s;
  s.precision(15);
  s << value;
  return s.str();
}
}  // namespace option_checks_detail

/// \throw OptionsError "the option KEY is VALUE; it must be RANGE", always.
[[noreturn]] inline void refuse_option(const std::string& key, const std::string& value, const std::string& range) {
  throw OptionsError("the option " + key + " is " + value + "; it must be " + range);
}

/// \throw OptionsError "the option KEY must be RANGE" unless ok.
inline void require(bool ok, const std::string& key, const std::string& range) {
  if (!ok) throw OptionsError("the option " + key + " must be " + range);
}

/// \throw OptionsError naming `key` unless lo <= value <= hi (a NaN is outside every range).
template <class T>
void require_in(const std::string& key, T value, T lo, T hi) {
  using option_checks_detail::text;
  if (!(value >= lo && value <= hi)) refuse_option(key, text(value), "in [" + text(lo) + ", " + text(hi) + "]");
}

/// \throw OptionsError naming `key` unless value >= lo.
template <class T>
void require_at_least(const std::string& key, T value, T lo) {
  using option_checks_detail::text;
  if (!(value >= lo)) refuse_option(key, text(value), "at least " + text(lo));
}

/// \throw OptionsError naming `key` unless value > 0 and finite.
inline void require_positive(const std::string& key, double value) {
  if (!(value > 0 && std::isfinite(value))) refuse_option(key, option_checks_detail::text(value), "a positive number");
}

}  // namespace mrsnake
