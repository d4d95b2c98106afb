#pragma once
/// \file model_files.h
/// The file handling that the single-structure model (model_io.h) and the model of many
/// structures (model_set.h) share: parts listed with their size and FNV-1a 64 checksum, the
/// manifest's own checksum, and which folder a model may replace. Internal to the model module.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/atomic_file.h"

namespace mrsnake::model_files {

constexpr const char* kManifest = "model.json";

/// 16 lowercase hex digits.
std::string hex64(std::uint64_t v);

/// \throw InputError if the file cannot be read.
std::vector<std::uint8_t> read_bytes(const std::filesystem::path& path);

/// \throw OutputError if the file cannot be written.
void write_bytes(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes);

/// {"path", "bytes", "fnv1a64"} of the file `name` (a path relative to `dir`).
nlohmann::json file_entry(const std::filesystem::path& dir, const std::string& name);

/// FNV-1a 64 of the compact dump of `manifest` without its key "manifest_fnv1a64".
std::string manifest_checksum(nlohmann::json manifest);

/// The folder without a trailing separator, lexically normal.
std::filesystem::path normalized_folder(const std::string& folder);

/// Reads one listed part, checking its name (a plain file name), presence, size and checksum.
/// \throw InputError naming the model, the part (`what`) and the defect.
std::vector<std::uint8_t> read_part(const std::filesystem::path& dir, const nlohmann::json& entry,
                                    const std::string& what);

/// The folder's normalized path, its parent folder created if needed.
/// \throw OutputError if the name is empty or the parent cannot be written.
std::string writable_model_path(const std::string& folder);

/// What a model may replace: a model folder (with its manifest) or an empty one.
ReplaceableFolder model_folder();

}  // namespace mrsnake::model_files
