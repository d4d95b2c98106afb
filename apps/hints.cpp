#include "apps/hints.h"

#include "apps/exit_codes.h"

namespace mrsnake::cli {

ExitCode exit_code_of(const Error& error) {
  if (dynamic_cast<const InputError*>(&error) || dynamic_cast<const TopologyError*>(&error)) return ExitCode::bad_input;
  if (dynamic_cast<const OutputError*>(&error)) return ExitCode::output;
  if (dynamic_cast<const AlgorithmError*>(&error)) return ExitCode::failed;
  if (dynamic_cast<const PartialFailure*>(&error)) return ExitCode::some_failed;
  return ExitCode::internal;
}

namespace {
// The flag that names a label value: segment's labels are its truth's.
std::string label_flag(const std::string& command) {
  return command == "segment" || command == "segment-batch" ? "--truth-label" : "--label";
}
}  // namespace

std::string hint_for(const Error& error, const std::string& command) {
  const int limit = error.remedy_limit();
  switch (error.remedy()) {
    case Remedy::none: return "";
    case Remedy::choose_label: return "choose one of those with " + label_flag(command);
    case Remedy::choose_component:
      return "give --component 1" + (limit > 1 ? " to " + std::to_string(limit) : std::string());
    case Remedy::other_resolution: return "try another --faces";
    case Remedy::other_initialization: return "use another --init";
    case Remedy::rebuild_model: return "rebuild it with mrsnake build-model";
    case Remedy::rebuild_model_with_image: return "rebuild the model with build-model --image";
    case Remedy::make_model: return "a model is a folder made by 'mrsnake build-model'";
    case Remedy::inspect_mesh: return "check it with 'mrsnake info'";
  }
  return "";
}

std::string message_with_hint(const Error& error, const std::string& command) {
  const std::string hint = hint_for(error, command);
  return hint.empty() ? std::string(error.what()) : std::string(error.what()) + "; " + hint;
}

}  // namespace mrsnake::cli
