#include "remesh/remesh_options_json.h"

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>

#include "mesh/errors.h"
#include "mesh/json_options.h"

namespace mrsnake {
namespace {

const std::pair<RelaxMode, const char*> kRelaxNames[] = {{RelaxMode::all_vertices, "all_vertices"},
                                                         {RelaxMode::new_vertices_only, "new_vertices_only"},
                                                         {RelaxMode::none, "none"}};
const std::pair<SphereMap, const char*> kSphereMapNames[] = {{SphereMap::automatic, "automatic"},
                                                             {SphereMap::punctured, "punctured"},
                                                             {SphereMap::two_halves, "two_halves"},
                                                             {SphereMap::hierarchical, "hierarchical"}};

const std::pair<ParameterDomain, const char*> kDomainNames[] = {{ParameterDomain::automatic, "automatic"},
                                                                {ParameterDomain::sphere, "sphere"},
                                                                {ParameterDomain::base_mesh, "base_mesh"}};
}  // namespace

void to_json(nlohmann::json& j, RelaxMode mode) { enum_to_json(j, mode, kRelaxNames); }
void from_json(const nlohmann::json& j, RelaxMode& mode) { enum_from_json(j, mode, kRelaxNames, "relax"); }
void to_json(nlohmann::json& j, ParameterDomain domain) { enum_to_json(j, domain, kDomainNames); }
void from_json(const nlohmann::json& j, ParameterDomain& domain) { enum_from_json(j, domain, kDomainNames, "domain"); }
void to_json(nlohmann::json& j, SphereMap map) { enum_to_json(j, map, kSphereMapNames); }
void from_json(const nlohmann::json& j, SphereMap& map) { enum_from_json(j, map, kSphereMapNames, "sphere_map"); }

}  // namespace mrsnake
