#include "apps/case_fingerprint.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <vector>

#include "mesh/errors.h"
#include "model/model_files.h"
#include "model/model_io.h"

namespace fs = std::filesystem;

namespace mrsnake::cli {
namespace {

std::uint64_t hash_text(const std::string& text, std::uint64_t state = kFnv1a64Start) {
  return fnv1a64(reinterpret_cast<const std::uint8_t*>(text.data()), text.size(), state);
}

// Continues `state` with the file's bytes, read in blocks (an image can be gigabytes).
std::uint64_t hash_file(const fs::path& path, std::uint64_t state) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot read '" + path.string() + "' to fingerprint it; check the path and permissions");
  std::vector<char> block(1 << 20);
  while (in) {
    in.read(block.data(), static_cast<std::streamsize>(block.size()));
    state = fnv1a64(reinterpret_cast<const std::uint8_t*>(block.data()), static_cast<std::size_t>(in.gcount()), state);
  }
  if (in.bad()) throw InputError("reading '" + path.string() + "' failed while fingerprinting it");
  return state;
}

// The data file a MetaImage (.mhd) or detached NRRD (.nhdr) header names; empty if none or a list.
fs::path detached_data_file(const fs::path& header) {
  const std::string ext = header.extension().string();
  const std::string key = ext == ".mhd" ? "ElementDataFile" : ext == ".nhdr" ? "data file" : "";
  if (key.empty()) return {};
  std::ifstream in(header);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(key, 0) != 0) continue;
    std::string value = line.substr(line.find_first_of("=:", key.size()) + 1);
    value.erase(0, value.find_first_not_of(" \t"));
    while (!value.empty() && (value.back() == '\r' || value.back() == ' ')) value.pop_back();
    if (value.empty() || value == "LOCAL" || value.rfind("LIST", 0) == 0 || value.find('%') != std::string::npos)
      return {};
    const fs::path data = value;
    return data.is_absolute() ? data : header.parent_path() / data;
  }
  return {};
}

}  // namespace

std::string image_fingerprint(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {  // a DICOM series folder
    std::vector<fs::path> files;
    for (const auto& e : fs::recursive_directory_iterator(path, ec))
      if (e.is_regular_file()) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    std::uint64_t h = kFnv1a64Start;
    for (const fs::path& f : files) h = hash_file(f, hash_text(fs::relative(f, path).string() + '\0', h));
    return model_files::hex64(h);
  }
  std::uint64_t h = hash_file(path, kFnv1a64Start);
  if (const fs::path data = detached_data_file(path); !data.empty()) h = hash_file(data, h);
  return model_files::hex64(h);
}

std::string model_fingerprint(const std::string& folder) {
  return model_files::hex64(hash_file(fs::path(folder) / model_files::kManifest, kFnv1a64Start));
}

std::string options_fingerprint(const nlohmann::json& options) { return model_files::hex64(hash_text(options.dump())); }

void to_json(nlohmann::json& j, const CaseFingerprint& f) {
  j = {{"image_fnv1a64", f.image},
       {"model_fnv1a64", f.model},
       {"options_fnv1a64", f.options},
       {"mrsnake_version", f.version}};
}

CaseFingerprint fingerprint_from_json(const nlohmann::json& j) {
  CaseFingerprint f;
  if (!j.is_object()) return f;
  const auto text = [&](const char* key) {
    return j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : std::string();
  };
  f.image = text("image_fnv1a64");
  f.model = text("model_fnv1a64");
  f.options = text("options_fnv1a64");
  f.version = text("mrsnake_version");
  return f;
}

}  // namespace mrsnake::cli
