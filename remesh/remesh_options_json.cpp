#include "remesh/remesh_options_json.h"

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>

#include "mesh/errors.h"

namespace mrsnake {
namespace {

template <class Enum, std::size_t N>
void enum_to_json(nlohmann::json& j, Enum value, const std::pair<Enum, const char*> (&names)[N]) {
  for (const auto& [e, name] : names)
    if (e == value) {
      j = name;
      return;
    }
  throw std::invalid_argument("an enum value without a name");
}

// Unlike NLOHMANN_JSON_SERIALIZE_ENUM, which maps an unknown string to the first value, a
// misspelt value is refused, naming the ones allowed.
template <class Enum, std::size_t N>
void enum_from_json(const nlohmann::json& j, Enum& value, const std::pair<Enum, const char*> (&names)[N],
                    const char* what) {
  std::string allowed;
  if (j.is_string())
    for (const auto& [e, name] : names)
      if (j.get<std::string>() == name) {
        value = e;
        return;
      }
  for (const auto& [e, name] : names) allowed += std::string(allowed.empty() ? "" : ", ") + '"' + name + '"';
  throw InputError(std::string("bad ") + what + " " + j.dump() + ": must be one of " + allowed);
}

const std::pair<RelaxMode, const char*> kRelaxNames[] = {{RelaxMode::all_vertices, "all_vertices"},
                                                         {RelaxMode::new_vertices_only, "new_vertices_only"},
                                                         {RelaxMode::none, "none"}};
const std::pair<SphereMap, const char*> kSphereMapNames[] = {{SphereMap::automatic, "automatic"},
                                                             {SphereMap::punctured, "punctured"},
                                                             {SphereMap::two_halves, "two_halves"},
                                                             {SphereMap::hierarchical, "hierarchical"}};

}  // namespace

void to_json(nlohmann::json& j, RelaxMode mode) { enum_to_json(j, mode, kRelaxNames); }
void from_json(const nlohmann::json& j, RelaxMode& mode) { enum_from_json(j, mode, kRelaxNames, "relax"); }
void to_json(nlohmann::json& j, SphereMap map) { enum_to_json(j, map, kSphereMapNames); }
void from_json(const nlohmann::json& j, SphereMap& map) { enum_from_json(j, map, kSphereMapNames, "sphere_map"); }

}  // namespace mrsnake
