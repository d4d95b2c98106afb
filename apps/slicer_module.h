#pragma once
/// \file slicer_module.h
/// `segment --xml` and `build-model --xml`: the commands as 3D Slicer CLI modules, described in
/// the Slicer Execution Model's XML (ModuleDescription.xsd). That schema types images and
/// surfaces as indexed parameters (`<index>`, no flag), so Slicer passes them as positional
/// arguments after the flags; every other parameter goes by its long flag (docs/slicer.md).
#include <string>
#include <utility>
#include <vector>

namespace mrsnake::cli {

/// The module description of `mrsnake segment`: the image (index 0), the label map (index 1)
/// and the surfaces (index 2) Slicer loads back, the model folder and the options by flag.
std::string segment_module_xml();

/// The module description of `mrsnake build-model`: the reference labels (index 0) and image
/// (index 1), the label values and the model folder by flag.
std::string build_model_module_xml();

/// Writes Slicer's return parameter file: one `name = value` line per entry.
/// \throw OutputError if it cannot be written.
void write_return_parameters(const std::string& path, const std::vector<std::pair<std::string, std::string>>& values);

}  // namespace mrsnake::cli
