#include "mesh/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>

#include "mesh/errors.h"

namespace fs = std::filesystem;

namespace mrsnake {

void ensure_writable_directory(const std::string& dir) {
  std::error_code ec;
  if (!dir.empty()) fs::create_directories(dir, ec);
  if (ec) throw OutputError("cannot create folder '" + dir + "': " + ec.message() + "; choose a writable output path");
  const std::string probe = (dir.empty() ? std::string(".") : dir);
  if (access(probe.c_str(), W_OK) != 0)
    throw OutputError("folder '" + probe + "' is not writable; choose a writable output path");
}

AtomicOutput::AtomicOutput(std::string final_path) : final_(std::move(final_path)) {
  static std::atomic<int> counter{0};
  const fs::path p(final_);
  ensure_writable_directory(p.parent_path().string());
  const std::string name = ".tmp-" + std::to_string(getpid()) + "-" + std::to_string(counter++) + "-" +
                           p.filename().string();
  temp_ = (p.parent_path() / name).string();
}

AtomicOutput::~AtomicOutput() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
}

void AtomicOutput::commit() {
  std::error_code ec;
  if (!fs::exists(temp_, ec)) throw OutputError("writing '" + final_ + "' produced no file");
  fs::rename(temp_, final_, ec);
  if (ec) throw OutputError("cannot move the output into place at '" + final_ + "': " + ec.message());
  committed_ = true;
}

void write_text_file_atomically(const std::string& path, const std::string& text) {
  AtomicOutput out(path);
  {
    std::ofstream f(out.temp_path(), std::ios::binary);
    f << text;
    f.close();
    if (!f) throw OutputError("cannot write '" + path + "'; check the free space and permissions");
  }
  out.commit();
}

}  // namespace mrsnake
