// libFuzzer harness: load_model on damaged model folders.
// A valid model (an icosphere hierarchy) is written once. Each input then replaces one part:
//   first byte even: model.json is the input (manifest parsing and validation);
//   first byte odd:  details.bin is the input, and the harness makes the checksums agree
//                    (its own trailing FNV and the manifest's), so that the fuzzer reaches
//                    the binary layout and count checks behind them.
// Any mrsnake::Error is a correct rejection; anything else is a bug.
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"
#include "mesh/primitives.h"
#include "model/shape_model.h"
#include "model/model_io.h"

namespace fs = std::filesystem;
using namespace mrsnake;

namespace {

const std::string& template_model() {
  static const std::string folder = [] {
    const std::string dir = "/tmp/mrsnake-fuzz-model-template-" + std::to_string(getpid());
    const TriMesh base = icosahedron(10.0);
    const auto conn = subdivide_connectivity(base.F, base.num_vertices(), 2);
    save_model(dir, make_model(conn, icosphere(2, 10.0).V));
    return dir;
  }();
  return folder;
}

void write_bytes(const fs::path& path, const std::uint8_t* data, std::size_t size) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

// The template's files (path relative to it, bytes), read once. Each input writes them out
// through streams, which retry an interrupted write: std::filesystem::copy does not, and
// libFuzzer's timer signal can interrupt its copy ("cannot copy: Interrupted system call").
const std::vector<std::pair<fs::path, std::string>>& template_files() {
  static const std::vector<std::pair<fs::path, std::string>> files = [] {
    std::vector<std::pair<fs::path, std::string>> read;
    const fs::path root = template_model();
    for (const fs::directory_entry& entry : fs::recursive_directory_iterator(root))
      if (entry.is_regular_file()) {
        std::ifstream in(entry.path(), std::ios::binary);
        read.emplace_back(fs::relative(entry.path(), root),
                          std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()));
      }
    return read;
  }();
  return files;
}

void write_template(const fs::path& work) {
  for (const auto& [relative, bytes] : template_files()) {
    fs::create_directories((work / relative).parent_path());
    write_bytes(work / relative, reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  }
}

std::string hex64(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const fs::path work = "/tmp/mrsnake-fuzz-model-" + std::to_string(getpid());
  fs::remove_all(work);
  write_template(work);
  const std::uint8_t* body = data + 1;
  const std::size_t body_size = size - 1;
  if (data[0] % 2 == 0) {
    write_bytes(work / "model.json", body, body_size);
  } else {
    std::vector<std::uint8_t> details(body, body + body_size);
    if (details.size() >= 8) {  // make details.bin's own checksum agree
      const std::uint64_t h = fnv1a64(details.data(), details.size() - 8);
      for (int b = 0; b < 8; ++b) details[details.size() - 8 + b] = static_cast<std::uint8_t>(h >> (8 * b));
    }
    write_bytes(work / "details.bin", details.data(), details.size());
    std::ifstream in(work / "model.json");
    nlohmann::json manifest = nlohmann::json::parse(in);
    manifest["files"]["details"]["bytes"] = details.size();
    manifest["files"]["details"]["fnv1a64"] = hex64(fnv1a64(details.data(), details.size()));
    manifest.erase("manifest_fnv1a64");
    const std::string compact = manifest.dump();
    manifest["manifest_fnv1a64"] =
        hex64(fnv1a64(reinterpret_cast<const std::uint8_t*>(compact.data()), compact.size()));
    std::ofstream(work / "model.json", std::ios::trunc) << manifest.dump(2);
  }
  try {
    const ShapeModel model = load_model(work.string());
    // An accepted model must be usable: synthesis of every level must run.
    if (model.base.rows() == 0) __builtin_trap();
  } catch (const mrsnake::Error&) {
  }
  return 0;
}
