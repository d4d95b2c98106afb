#pragma once
/// \file model_set.h
/// A model of one or more structures (format version 2): one folder holding each
/// structure's shape model as a version-1 folder `structures/<value>/` (model_io.h), their
/// label values, names and colours, the labels that were asked for but skipped and why, and
/// one reference image crop that covers them all, so that a segmentation registers once.
/// A version-1 folder (one structure) still reads, as a model of that one structure.
/// Layout and rules: docs/model-format.md.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/progress.h"
#include "model/label_names.h"
#include "model/model_io.h"
#include "model/shape_model.h"

namespace mrsnake {

/// One structure of a model: the label value it was built from, its name and colour, and
/// its shape model.
struct ModelStructure {
  int value = 1;
  LabelName label;
  ShapeModel model;
};

/// A label that was asked for (build-model --label all) but has no model, and why.
struct SkippedLabel {
  int value = 0;
  std::string name;
  std::string reason;
};

struct ModelSet {
  std::vector<ModelStructure> structures;  ///< in increasing label value
  std::vector<SkippedLabel> skipped;
  /// The shared reference crop, in the reference_image section's layout (model/sections.h);
  /// empty without one. A version-1 folder keeps its crop in its structure's own sections.
  std::vector<std::uint8_t> reference_image;
  std::string source_image;  ///< the label image (empty if unknown)
  std::optional<PhysicalFrame> physical_frame;
  /// The options the structures were built with, as `build-model --config` reads them; null if unknown.
  nlohmann::json build_options;
  int format_version = kModelFormatVersion;  ///< as read: 1 for a folder of one structure
};

/// Writes the model atomically: every part goes to a temporary folder beside `folder`, which
/// is renamed into place at the end; an existing model folder there is replaced.
/// `write_extras` is called with the temporary folder before the rename (e.g. report.html).
/// \pre set.structures is not empty, their values distinct and positive; each model holds its
///      levels S_0..S_L.
/// \throw OutputError if the folder cannot be written or the path holds something else.
void save_model_set(const std::string& folder, const ModelSet& set, const ProgressFn& progress = {},
                    const std::function<void(const std::string& temp_folder)>& write_extras = {});

/// Reads and validates a model folder of either version: every structure as load_model
/// reads it, and for version 2 the manifest's list against each structure's own manifest
/// (its checksum) and the shared reference crop (size and checksum).
/// \throw InputError naming the model, the part and the defect; never returns a partial model.
ModelSet load_model_set(const std::string& folder, const LoadModelOptions& options = {});

}  // namespace mrsnake
