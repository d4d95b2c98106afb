#include "model/build_model_set.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>

#include "mesh/errors.h"
#include "model/snake_adapter.h"
#include "snake/reference_image.h"

namespace mrsnake {
namespace {

// Every label value in the volume but the background.
std::vector<int> values_present(const Volume& labels) {
  std::set<int> values;
  for (const float v : labels.data) {
    const long rounded = std::lround(v);
    if (rounded > 0 && rounded <= 32767) values.insert(static_cast<int>(rounded));
  }
  return {values.begin(), values.end()};
}

LabelName name_of(int value, const std::map<int, LabelName>& names) {
  if (const auto it = names.find(value); it != names.end()) return it->second;
  return {default_label_name(value), default_label_color(value)};
}

// Every structure's finest level, stacked: what the shared crop must cover.
RowMatrixX3d stacked_finest_levels(const std::vector<BuiltStructure>& structures) {
  Eigen::Index rows = 0;
  for (const BuiltStructure& s : structures) rows += s.built.model.level_positions.back().rows();
  RowMatrixX3d V(rows, 3);
  Eigen::Index at = 0;
  for (const BuiltStructure& s : structures) {
    const RowMatrixX3d& P = s.built.model.level_positions.back();
    V.middleRows(at, P.rows()) = P;
    at += P.rows();
  }
  return V;
}

// One reference crop for all: the structures' margins differ, the largest covers each.
void add_shared_reference(const Volume& image, BuiltModelSet& set) {
  ReferenceImageOptions ro;
  ro.margin_mm = 0;
  for (const BuiltStructure& s : set.structures)
    ro.margin_mm = std::max(ro.margin_mm, s.built.reference_margin_mm.value_or(0.0));
  set.reference_margin_mm = ro.margin_mm;
  set.reference_image = reference_image_section(image, stacked_finest_levels(set.structures), ro);
}

}  // namespace

LabelSelection parse_label_selection(const std::string& text) {
  LabelSelection selection;
  if (text == "all") {
    selection.all = true;
    return selection;
  }
  std::stringstream in(text);
  std::set<int> seen;
  for (std::string item; std::getline(in, item, ',');) {
    char* end = nullptr;
    const long v = std::strtol(item.c_str(), &end, 10);
    if (item.empty() || *end != '\0' || v <= 0 || v > 32767)
      throw InputError("--label '" + text + "': '" + item +
                       "' is not a label value (a positive integer); give values such as 1,3,7, or all");
    if (!seen.insert(static_cast<int>(v)).second)
      throw InputError("--label '" + text + "' gives the value " + item + " twice");
    selection.values.push_back(static_cast<int>(v));
  }
  if (selection.values.empty()) throw InputError("--label is empty; give values such as 1,3,7, or all");
  std::sort(selection.values.begin(), selection.values.end());
  return selection;
}

ModelSet BuiltModelSet::model_set(const std::string& source_image) const {
  ModelSet set;
  set.source_image = source_image;
  set.skipped = skipped;
  set.reference_image = reference_image;
  for (const BuiltStructure& s : structures) {
    ModelStructure m{s.value, s.label, s.built.model};
    m.model.source_image = source_image;
    if (!reference_image.empty()) m.model.sections.erase(kReferenceImageSection);
    set.structures.push_back(std::move(m));
  }
  set.physical_frame = structures.front().built.model.physical_frame;
  set.build_options = structures.front().built.model.build_options;
  set.build_options.erase("label");  // the structures' values are listed with them
  return set;
}

BuiltModelSet build_model_set(const Volume& labels, const Volume* image, const LabelSelection& selection,
                              const std::map<int, LabelName>& names, const BuildModelOptions& options,
                              const ProgressFn& progress, const StructureProgressFn& on_structure) {
  validate(options);
  const std::vector<int> values = selection.all ? values_present(labels) : selection.values;
  if (values.empty()) throw InputError("the label volume holds no label but the background (0)", Remedy::choose_label);
  BuiltModelSet set;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const LabelName label = name_of(values[i], names);
    if (on_structure) on_structure(values[i], label.name, static_cast<int>(i), static_cast<int>(values.size()));
    BuildModelOptions o = options;
    o.label = values[i];
    try {
      set.structures.push_back({values[i], label, build_model(labels, image, o, progress)});
    } catch (const Error& e) {
      // `all` takes what can be modelled; a label asked for by number must build.
      if (!selection.all || dynamic_cast<const OptionsError*>(&e) != nullptr) throw;
      set.skipped.push_back({values[i], label.name, e.what()});
    }
  }
  if (set.structures.empty())
    throw InputError("none of the " + std::to_string(values.size()) +
                     " labels could be modelled (each is listed with its reason above); choose labels with --label");
  if (image != nullptr) add_shared_reference(*image, set);
  return set;
}

}  // namespace mrsnake
