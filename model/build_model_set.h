#pragma once
/// \file build_model_set.h
/// One model of many structures from one reference label volume: build_model() for each
/// label, then one reference image crop around all of them (model_set.h), so that a
/// segmentation registers once for every structure.
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "mesh/progress.h"
#include "mesh/volume.h"
#include "model/build_model.h"
#include "model/label_names.h"
#include "model/model_set.h"

namespace mrsnake {

/// Which labels to model.
struct LabelSelection {
  std::vector<int> values;  ///< the labels asked for, each must build
  /// Every label value present but 0; those that cannot be modelled (not closed genus 0 after
  /// the tunnel closing, a poor fit, too small) are skipped with the reason.
  bool all = false;
};

/// Parses `--label`: "all", or values separated by commas ("1,3,7").
/// \throw InputError naming what is wrong (an empty list, a value that is not a positive integer,
///        a value repeated).
LabelSelection parse_label_selection(const std::string& text);

/// One structure as build_model() made it.
struct BuiltStructure {
  int value = 0;
  LabelName label;
  BuiltModel built;
};

struct BuiltModelSet {
  std::vector<BuiltStructure> structures;  ///< in increasing value
  std::vector<SkippedLabel> skipped;
  std::vector<std::uint8_t> reference_image;  ///< the shared crop's section (with an image)
  double reference_margin_mm = 0;             ///< its margin: the largest of the structures' own

  /// The model to save: every structure's model without its own crop, and the shared one.
  ModelSet model_set(const std::string& source_image) const;
};

/// What build_model_set() reports before and after each structure.
using StructureProgressFn = std::function<void(int value, const std::string& name, int index, int count)>;

/// Builds a model of each selected label with `options` (options.label is ignored), names
/// them from `names` (default_label_name otherwise), and crops the reference image once
/// around all of them.
/// \pre image, when given, lies in the physical space of labels.
/// \throw OptionsError as validate(); InputError if a value asked for is absent or `all` finds
///        no label to model; the errors of build_model() for a value asked for by number.
BuiltModelSet build_model_set(const Volume& labels, const Volume* image, const LabelSelection& selection,
                              const std::map<int, LabelName>& names, const BuildModelOptions& options,
                              const ProgressFn& progress = {}, const StructureProgressFn& on_structure = {});

}  // namespace mrsnake
