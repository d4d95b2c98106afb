#pragma once
/// \file label_names.h
/// Names and colours of label values, as a model keeps them and its outputs show them: read
/// from an ITK-SNAP label description file or a CSV of `value,name` rows, or numbered by default.
#include <array>
#include <map>
#include <string>

namespace mrsnake {

/// One label value's name and display colour (0..255 per channel).
struct LabelName {
  std::string name;
  std::array<int, 3> color{0, 0, 0};
};

/// The name a label without one gets: "label N".
std::string default_label_name(int value);

/// A colour per value from a fixed palette of well-separated hues (the same value always
/// gets the same colour; neighbouring values get different ones).
std::array<int, 3> default_label_color(int value);

/// Reads label names from `path`, by its content:
/// - an ITK-SNAP label description file: rows `IDX R G B A VIS MSH "NAME"`, `#` comments;
/// - a CSV: rows `value,name[,...]`, the name possibly quoted; a first row whose value is not
///   an integer is a header; further columns are ignored. Colours come from default_label_color.
/// Value 0 (the background) is kept if listed; callers skip it.
/// \throw InputError if the file cannot be read, a row is malformed (its line named), a value
///        repeats, or no row is found.
std::map<int, LabelName> read_label_names(const std::string& path);

}  // namespace mrsnake
