#pragma once
/// \file json_text.h
/// JSON text for files and the terminal.
#include <string>

#include <nlohmann/json.hpp>

namespace mrsnake {

/// j.dump(indent), except that bytes of a string that are not UTF-8 (a file name in another
/// encoding) become U+FFFD instead of throwing: a report must not fail on a path.
inline std::string json_text(const nlohmann::json& j, int indent = -1) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace mrsnake
