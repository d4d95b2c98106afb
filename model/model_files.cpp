#include "model/model_files.h"

#include <cstdio>
#include <fstream>
#include <iterator>

#include "mesh/errors.h"
#include "mesh/json_text.h"
#include "model/model_io.h"

namespace fs = std::filesystem;

namespace mrsnake::model_files {

std::string hex64(std::uint64_t v) {
  char s[17];
  std::snprintf(s, sizeof s, "%016llx", static_cast<unsigned long long>(v));
  return s;
}

std::vector<std::uint8_t> read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot read '" + path.string() + "'; check its permissions");
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_bytes(const fs::path& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw OutputError("cannot write '" + path.string() + "'; check the free space and permissions");
}

nlohmann::json file_entry(const fs::path& dir, const std::string& name) {
  const std::vector<std::uint8_t> bytes = read_bytes(dir / name);
  return {{"path", name}, {"bytes", bytes.size()}, {"fnv1a64", hex64(fnv1a64(bytes.data(), bytes.size()))}};
}

std::string manifest_checksum(nlohmann::json manifest) {
  manifest.erase("manifest_fnv1a64");
  const std::string text = json_text(manifest);
  return hex64(fnv1a64(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

fs::path normalized_folder(const std::string& folder) {
  fs::path p = fs::path(folder).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  return p;
}

std::vector<std::uint8_t> read_part(const fs::path& dir, const nlohmann::json& entry, const std::string& what) {
  const std::string name = entry.at("path").get<std::string>();
  if (name.empty() || name.find('/') != std::string::npos || name.find('\\') != std::string::npos || name == "." ||
      name == "..")
    throw InputError("model '" + dir.string() + "' lists an invalid file name '" + name + "' for its " + what);
  const fs::path path = dir / name;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    throw InputError("model '" + dir.string() + "' is missing its part '" + name + "' (" + what +
                     "); the model is incomplete: rebuild it");
  std::vector<std::uint8_t> bytes = read_bytes(path);
  const std::uint64_t expected = entry.at("bytes").get<std::uint64_t>();
  if (bytes.size() < expected)
    throw InputError("part '" + name + "' of model '" + dir.string() + "' is truncated (" +
                     std::to_string(bytes.size()) + " of " + std::to_string(expected) + " bytes); rebuild the model");
  if (bytes.size() > expected)
    throw InputError("part '" + name + "' of model '" + dir.string() + "' has " + std::to_string(bytes.size()) +
                     " bytes where the manifest says " + std::to_string(expected) +
                     "; it was altered: rebuild the model");
  if (hex64(fnv1a64(bytes.data(), bytes.size())) != entry.at("fnv1a64").get<std::string>())
    throw InputError("part '" + name + "' of model '" + dir.string() +
                     "' was altered or corrupted (checksum mismatch); rebuild the model");
  return bytes;
}

std::string writable_model_path(const std::string& folder) {
  const fs::path final_path = normalized_folder(folder);
  if (final_path.empty()) throw OutputError("empty model folder name; give a path such as brain.model");
  const fs::path parent = final_path.has_parent_path() ? final_path.parent_path() : fs::path(".");
  ensure_writable_directory(parent.string());
  return final_path.string();
}

ReplaceableFolder model_folder() {
  return {[](const fs::path& folder) {
            std::error_code ec;
            return fs::is_directory(folder, ec) && (fs::exists(folder / kManifest, ec) || fs::is_empty(folder, ec));
          },
          "a model folder"};
}

}  // namespace mrsnake::model_files
