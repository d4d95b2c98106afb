#pragma once
/// \file model_io.h
/// The shape model on disk: a folder holding model.json (the manifest), details.bin (S_0's
/// faces and positions and the details D_1..D_L), level_j.vtp (every level S_j, for
/// ParaView / 3D Slicer) and optional named sections. Layout and rules: docs/model-format.md.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "mesh/progress.h"
#include "model/shape_model.h"

namespace mrsnake {

/// The newest model format this build reads: version 2 is a model of one or more structures
/// (model_set.h), each kept as a version-1 folder of one structure, which save_model writes.
constexpr int kModelFormatVersion = 2;
/// The format of one structure's folder (save_model, load_model).
constexpr int kStructureFormatVersion = 1;

/// FNV-1a 64's starting state.
constexpr std::uint64_t kFnv1a64Start = 14695981039346656037ull;

/// FNV-1a 64-bit hash of a byte range (the checksum of every model part). `state` continues
/// a hash: fnv1a64(b, n, fnv1a64(a, m)) is the hash of a followed by b.
std::uint64_t fnv1a64(const std::uint8_t* data, std::size_t size, std::uint64_t state = kFnv1a64Start);

/// Writes the model folder atomically: everything goes to a temporary folder beside it,
/// which is renamed into place at the end. An existing model folder at that path is replaced.
/// \pre model.level_positions holds S_0..S_L (as make_model fills it).
/// `write_extras`, when given, is called with the temporary folder after every model part is
/// written and before the rename, to add files that are not part of the model (e.g.
/// report.html); they are not listed in the manifest. What it throws aborts the save.
/// \throw OutputError if the folder cannot be written, or if the path exists and is not a
///        model folder (nothing is removed then).
void save_model(const std::string& folder, const ShapeModel& model, const ProgressFn& progress = {},
                const std::function<void(const std::string& temp_folder)>& write_extras = {});

struct LoadModelOptions {
  bool level_meshes = false;  ///< also read level_j.vtp into level_positions
};

/// Reads and validates a model folder: manifest version and checksum, every part present
/// with its size and checksum, the binary layout and its own checksum, and the counts
/// against the connectivity.
/// \throw InputError with a message naming the model, the part and the defect (missing,
///        truncated, altered, newer version, inconsistent), or if the folder is a model of
///        structures (format version 2: read it with load_model_set); never returns a partial model.
ShapeModel load_model(const std::string& folder, const LoadModelOptions& options = {});

/// The validated manifest (model.json) of a model folder, without reading the other parts.
/// \throw InputError as load_model does for the manifest.
nlohmann::json read_model_manifest(const std::string& folder);

}  // namespace mrsnake
