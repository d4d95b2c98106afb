#pragma once
/// \file json_options.h
/// Options structs as JSON: the form of `--config FILE` and of the `options` key of every
/// report.json, so that a run can be repeated exactly. A struct opts in with nlohmann's
/// NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT (missing keys keep their defaults);
/// options_from_json adds the check that no key is misspelt.
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"

namespace mrsnake {

namespace detail {
// Every key of `given` must name a key of `known` (the defaults written out), recursively
// through nested objects; `path` names the place for the message.
inline void check_known_keys(const nlohmann::json& given, const nlohmann::json& known, const std::string& path) {
  if (!given.is_object()) {
    if (known.is_object()) throw InputError("the options key '" + path + "' must be an object of options");
    return;
  }
  if (!known.is_object()) throw InputError("the options key '" + path + "' takes a value, not an object");
  for (const auto& [key, value] : given.items()) {
    const std::string where = path.empty() ? key : path + "." + key;
    if (!known.contains(key)) throw InputError("unknown options key '" + where + "'");
    check_known_keys(value, known.at(key), where);
  }
}
}  // namespace detail

/// Options of type T from JSON: the keys given replace T's defaults, the rest keep them.
/// \throw InputError on a key T does not have, or a value of the wrong type.
template <class T>
T options_from_json(const nlohmann::json& j) {
  const nlohmann::json defaults = T{};
  detail::check_known_keys(j, defaults, "");
  try {
    return j.get<T>();
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string("bad options value: ") + e.what());
  }
}

/// Options of type T from a JSON file (see options_from_json).
/// \throw InputError if the file cannot be read, is not JSON, or has an unknown key.
template <class T>
T read_options_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot read the options file " + path);
  std::stringstream text;
  text << in.rdbuf();
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text.str());
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(path + " is not JSON: " + e.what());
  }
  try {
    return options_from_json<T>(j);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
}

}  // namespace mrsnake
