#pragma once
/// \file build_model_json.h
/// BuildModelOptions as JSON: the form of `mrsnake build-model --config FILE` and of the
/// "build_options" key of model.json, so that a model can be built again exactly. Keys are the
/// field names, nested as the structs; a missing key keeps the preset's value. Read with
/// options_from_json / read_options_file (mesh/json_options.h), which refuse unknown keys.
#include <nlohmann/json.hpp>

#include "model/build_model.h"
#include "remesh/remesh_options_json.h"

namespace mrsnake {

/// "linear", "butterfly". \throw InputError on another string.
void to_json(nlohmann::json& j, PredictScheme scheme);
void from_json(const nlohmann::json& j, PredictScheme& scheme);
/// "global", "local". \throw InputError on another string.
void to_json(nlohmann::json& j, DetailFrame frame);
void from_json(const nlohmann::json& j, DetailFrame& frame);
/// "automatic", "edges", "labels". \throw InputError on another string.
void to_json(nlohmann::json& j, ProfileAlignment alignment);
void from_json(const nlohmann::json& j, ProfileAlignment& alignment);

NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(WaveletOptions, predict, update, frame, degenerate_frame_tolerance)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(AppearanceOptions, half_length, shell_voxels, alignment,
                                                clean_edge_max_residual, max_alignment_voxels)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(ModelSurfaceOptions, mc_spacing_mm, smoothing_iterations, close_tunnels,
                                                remove_spurs)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(ModelReportOptions, level_stats, compare_unrelaxed)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(BuildModelOptions, label, component, surface, faces, levels, remesh,
                                                wavelet, appearance, reference_margin_mm, allow_poor_fit, report)

}  // namespace mrsnake
