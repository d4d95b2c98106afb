#include "model/build_model_json.h"

#include <utility>

#include "mesh/json_options.h"

namespace mrsnake {
namespace {

const std::pair<PredictScheme, const char*> kPredictNames[] = {{PredictScheme::linear, "linear"},
                                                               {PredictScheme::butterfly, "butterfly"}};
const std::pair<DetailFrame, const char*> kFrameNames[] = {{DetailFrame::global, "global"},
                                                           {DetailFrame::local, "local"}};
const std::pair<ProfileAlignment, const char*> kAlignmentNames[] = {{ProfileAlignment::automatic, "automatic"},
                                                                    {ProfileAlignment::edges, "edges"},
                                                                    {ProfileAlignment::labels, "labels"}};

}  // namespace

void to_json(nlohmann::json& j, PredictScheme scheme) { enum_to_json(j, scheme, kPredictNames); }
void from_json(const nlohmann::json& j, PredictScheme& scheme) { enum_from_json(j, scheme, kPredictNames, "predict"); }
void to_json(nlohmann::json& j, DetailFrame frame) { enum_to_json(j, frame, kFrameNames); }
void from_json(const nlohmann::json& j, DetailFrame& frame) { enum_from_json(j, frame, kFrameNames, "frame"); }
void to_json(nlohmann::json& j, ProfileAlignment alignment) { enum_to_json(j, alignment, kAlignmentNames); }
void from_json(const nlohmann::json& j, ProfileAlignment& alignment) {
  enum_from_json(j, alignment, kAlignmentNames, "alignment");
}

}  // namespace mrsnake
