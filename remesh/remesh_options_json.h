#pragma once
/// \file remesh_options_json.h
/// RemeshOptions and its stage options as JSON: the form of `mrsnake remesh --config FILE` and
/// of the "options" key of remesh's report.json. Keys are the field names, nested as the
/// structs; a missing key keeps its default. Read with options_from_json / read_options_file
/// (mesh/json_options.h), which refuse unknown keys. The caller-only fields of RemeshOptions
/// (keep_input_locator, compute_stats, progress) are not part of it.
#include <nlohmann/json.hpp>

#include "remesh/remesh.h"

namespace mrsnake {

/// "all_vertices", "new_vertices_only", "none". \throw InputError on another string.
void to_json(nlohmann::json& j, RelaxMode mode);
void from_json(const nlohmann::json& j, RelaxMode& mode);

/// "sphere", "base_mesh". \throw InputError on another string.
void to_json(nlohmann::json& j, ParameterDomain domain);
void from_json(const nlohmann::json& j, ParameterDomain& domain);

/// "automatic", "punctured", "two_halves", "hierarchical". \throw InputError on another string.
void to_json(nlohmann::json& j, SphereMap map);
void from_json(const nlohmann::json& j, SphereMap& map);

NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SimplifyOptions, above_faces, sliver_share)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SizingOptions, curvature_weight, curvature_exponent, density_exponent)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(BaseMeshOptions, density_exponent, density_smoothing, max_bend,
                                                rim_min_triangles, one_chart_flip_margin_deg)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(RelaxationOptions, lloyd_iterations, shape_iterations,
                                                guarded_shape_iterations, surface_iterations, surface_quality_floor,
                                                smooth_rim)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(FeatureSnapOptions, max_snaps, min_distance, min_quality, min_angle_deg,
                                                min_gain, min_share_of_largest)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(RepairOptions, sweeps, threshold, coarse_levels, guard_finest,
                                                error_tolerance, after_reprojection)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SurfaceFitOptions, rounds, regularization, max_offset,
                                                max_sample_distance, quality_floor)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(UntangleOptions, max_rounds)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(RemeshOptions, levels, target_faces, base_vertices, relax, domain,
                                                sphere_map, base_mesh_alone_when_squeezed, simplify, sizing, base,
                                                relaxation, snap, repair, fit, untangle)

}  // namespace mrsnake
