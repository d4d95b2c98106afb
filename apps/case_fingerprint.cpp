#include "apps/case_fingerprint.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
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

// The data file a MetaImage (.mhd), detached NRRD (.nhdr) or Analyze (.hdr) header puts its
// voxels in: empty when the header holds them itself; nullopt when it names files this cannot
// follow (a list, a pattern), so that the image is never taken as unchanged.
std::optional<fs::path> detached_data_file(const fs::path& header) {
  const std::string ext = header.extension().string();
  if (ext == ".hdr") return fs::path(header).replace_extension(".img");
  if (ext != ".mhd" && ext != ".nhdr") return fs::path();
  std::ifstream in(header);
  for (std::string line; std::getline(in, line);) {
    const bool meta = ext == ".mhd" && line.rfind("ElementDataFile", 0) == 0;
    const bool nrrd = ext == ".nhdr" && (line.rfind("data file:", 0) == 0 || line.rfind("datafile:", 0) == 0);
    if (!meta && !nrrd) continue;
    std::string value = line.substr(line.find_first_of(meta ? "=" : ":") + 1);
    value.erase(0, value.find_first_not_of(" \t"));
    while (!value.empty() && (value.back() == '\r' || value.back() == ' ')) value.pop_back();
    if (value == "LOCAL") return fs::path();
    if (value.empty() || value.rfind("LIST", 0) == 0 || value.find('%') != std::string::npos ||
        value.find(' ') != std::string::npos)
      return std::nullopt;
    const fs::path data = value;
    return data.is_absolute() ? data : header.parent_path() / data;
  }
  return fs::path();
}

// A DICOM folder's files, in name order.
// \throw InputError if the folder cannot be listed.
std::vector<fs::path> folder_files(const std::string& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  fs::recursive_directory_iterator it(dir, fs::directory_options::skip_permission_denied, ec), end;
  for (; !ec && it != end; it.increment(ec))
    if (it->is_regular_file(ec)) files.push_back(it->path());
  if (ec) throw InputError("cannot list the DICOM folder '" + dir + "' to fingerprint it: " + ec.message());
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

std::string image_fingerprint(const std::string& path, const std::string& series) {
  std::error_code ec;
  std::uint64_t h = hash_text(series + '\0');
  if (fs::is_directory(path, ec)) {  // a DICOM series folder
    for (const fs::path& f : folder_files(path)) h = hash_file(f, hash_text(fs::relative(f, path).string() + '\0', h));
    return model_files::hex64(h);
  }
  h = hash_file(path, h);
  const std::optional<fs::path> data = detached_data_file(path);
  if (!data) return "unfollowed-data-files";  // matches no fingerprint of a result: always redone
  if (!data->empty()) h = hash_file(*data, h);
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
