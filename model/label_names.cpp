#include "model/label_names.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

#include "mesh/errors.h"

namespace mrsnake {
namespace {

std::string trimmed(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return "";
  const auto last = text.find_last_not_of(" \t\r\n");
  return text.substr(first, last - first + 1);
}

bool parse_int(const std::string& text, int& value) {
  const std::string t = trimmed(text);
  if (t.empty()) return false;
  char* end = nullptr;
  const long v = std::strtol(t.c_str(), &end, 10);
  if (*end != '\0' || v < 0 || v > 32767) return false;
  value = static_cast<int>(v);
  return true;
}

// The fields of one CSV row; a quoted field may hold commas and doubled quotes.
std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
      fields.back() += '"';
      ++i;
    } else if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

// An ITK-SNAP row: seven numbers, then the quoted name.
bool parse_itksnap_row(const std::string& line, int& value, LabelName& label) {
  const auto quote = line.find('"');
  const auto end_quote = line.rfind('"');
  if (quote == std::string::npos || end_quote == quote) return false;
  std::istringstream numbers(line.substr(0, quote));
  double fields[7];
  for (double& f : fields)
    if (!(numbers >> f)) return false;
  std::string rest;
  if (numbers >> rest) return false;
  if (!(fields[0] >= 0 && fields[0] <= 32767)) return false;
  value = static_cast<int>(fields[0]);
  if (fields[0] != value) return false;
  for (int c = 0; c < 3; ++c) {
    if (!(fields[1 + c] >= 0 && fields[1 + c] <= 255)) return false;
    label.color[c] = static_cast<int>(fields[1 + c]);
  }
  label.name = line.substr(quote + 1, end_quote - quote - 1);
  return true;
}

bool is_itksnap_file(const std::vector<std::string>& rows) {
  for (const std::string& row : rows) {
    int value = 0;
    LabelName label;
    if (!parse_itksnap_row(row, value, label)) return false;
  }
  return true;
}

void add_name(std::map<int, LabelName>& names, int value, LabelName label, const std::string& where) {
  if (!names.emplace(value, std::move(label)).second)
    throw InputError(where + " names the value " + std::to_string(value) + " twice; keep one row per value");
}

}  // namespace

std::string default_label_name(int value) { return "label " + std::to_string(value); }

std::array<int, 3> default_label_color(int value) {
  // Hues 137.5° apart (the golden angle): neighbouring values are far apart on the wheel.
  const double hue = std::fmod(value * 137.508, 360.0) / 60.0;
  const double x = 1.0 - std::fabs(std::fmod(hue, 2.0) - 1.0);
  const int sector = static_cast<int>(hue) % 6;
  const double rgb[6][3] = {{1, x, 0}, {x, 1, 0}, {0, 1, x}, {0, x, 1}, {x, 0, 1}, {1, 0, x}};
  std::array<int, 3> color{};
  for (int c = 0; c < 3; ++c) color[c] = static_cast<int>(std::lround(40 + 215 * rgb[sector][c]));
  return color;
}

std::map<int, LabelName> read_label_names(const std::string& path) {
  std::ifstream in(path);
  if (!in)
    throw InputError("cannot read the label names '" + path +
                     "'; give an ITK-SNAP label description file or a CSV of value,name rows");
  std::vector<std::string> rows;
  std::vector<int> line_numbers;
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    const std::string t = trimmed(line);
    if (t.empty() || t[0] == '#') continue;
    rows.push_back(t);
    line_numbers.push_back(number);
  }
  std::map<int, LabelName> names;
  const bool itksnap = !rows.empty() && is_itksnap_file(rows);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::string where = "line " + std::to_string(line_numbers[i]) + " of the label names '" + path + "'";
    int value = 0;
    LabelName label;
    if (itksnap) {
      parse_itksnap_row(rows[i], value, label);
      add_name(names, value, std::move(label), where);
      continue;
    }
    const std::vector<std::string> fields = csv_fields(rows[i]);
    if (!parse_int(fields[0], value)) {
      if (i == 0) continue;  // the header
      throw InputError(where + " does not start with a label value (an integer 0 to 32767): '" + rows[i] + "'");
    }
    label.name = fields.size() > 1 ? trimmed(fields[1]) : "";
    if (label.name.empty()) throw InputError(where + " has no name after the value " + std::to_string(value));
    label.color = default_label_color(value);
    add_name(names, value, std::move(label), where);
  }
  if (names.empty())
    throw InputError("the label names '" + path +
                     "' hold no row; give an ITK-SNAP label description file or a CSV of value,name rows");
  return names;
}

}  // namespace mrsnake
