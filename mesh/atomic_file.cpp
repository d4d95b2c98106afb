#include "mesh/atomic_file.h"

#include <fcntl.h>
#include <sys/syscall.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>

#include "mesh/errors.h"

namespace fs = std::filesystem;

namespace mrsnake {
namespace {

// Live temporaries, removed by the interrupt handler. Kept as a fixed table of C strings so
// the handler does not allocate.
constexpr int kMaxLive = 64;
constexpr int kMaxPath = 4096;
char g_live[kMaxLive][kMaxPath];
volatile sig_atomic_t g_used[kMaxLive];
std::mutex g_live_mutex;

int register_temp(const std::string& path) {
  std::lock_guard<std::mutex> lock(g_live_mutex);
  if (path.size() >= kMaxPath) return -1;
  for (int i = 0; i < kMaxLive; ++i)
    if (!g_used[i]) {
      std::memcpy(g_live[i], path.c_str(), path.size() + 1);
      g_used[i] = 1;
      return i;
    }
  return -1;
}

void unregister_temp(int slot) {
  if (slot < 0) return;
  std::lock_guard<std::mutex> lock(g_live_mutex);
  g_used[slot] = 0;
}

// `dir` + "/" + `name` into `out` (kMaxPath bytes) without the C library's formatting.
bool join_path(const char* dir, const char* name, char* out) {
  const std::size_t a = std::strlen(dir), b = std::strlen(name);
  if (a + 1 + b >= static_cast<std::size_t>(kMaxPath)) return false;
  std::memcpy(out, dir, a);
  out[a] = '/';
  std::memcpy(out + a + 1, name, b + 1);
  return true;
}

// The entries getdents64 returns, as the kernel lays them out.
struct KernelDirent {
  ino64_t inode;
  off64_t offset;
  unsigned short length;
  unsigned char type;
  char name[1];
};

// Removes a file or a folder tree with system calls only: it runs in the signal handler, which
// may have interrupted malloc, so nothing here may allocate (opendir does).
void remove_tree(const char* path) {
  struct stat st;
  if (lstat(path, &st) != 0) return;
  if (!S_ISDIR(st.st_mode)) {
    unlink(path);
    return;
  }
  // Entries removed while the folder is read may hide others: read it again until it is empty.
  for (int pass = 0; rmdir(path) != 0 && pass < 8; ++pass) {
    const int fd = open(path, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return;
    alignas(KernelDirent) char buffer[4096];
    for (long n; (n = syscall(SYS_getdents64, fd, buffer, sizeof buffer)) > 0;)
      for (long at = 0; at < n;) {
        const auto* e = reinterpret_cast<const KernelDirent*>(buffer + at);
        at += e->length;
        if (!std::strcmp(e->name, ".") || !std::strcmp(e->name, "..")) continue;
        char child[kMaxPath];
        if (join_path(path, e->name, child)) remove_tree(child);
      }
    close(fd);
  }
}

extern "C" void on_interrupt(int sig) {
  for (int i = 0; i < kMaxLive; ++i)
    if (g_used[i]) remove_tree(g_live[i]);
  const char msg[] = "\nmrsnake: interrupted; partial outputs removed\n";
  [[maybe_unused]] auto ignored = write(STDERR_FILENO, msg, sizeof msg - 1);
  _exit(128 + sig);
}

std::string temp_name_beside(const std::string& final_path) {
  static std::atomic<int> counter{0};
  const fs::path p(final_path);
  return (p.parent_path() /
          (".tmp-" + std::to_string(getpid()) + "-" + std::to_string(counter++) + "-" + p.filename().string()))
      .string();
}

}  // namespace

void install_interrupt_cleanup() {
  struct sigaction sa {};
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

void ensure_writable_directory(const std::string& dir) {
  std::error_code ec;
  if (!dir.empty()) fs::create_directories(dir, ec);
  if (ec) throw OutputError("cannot create folder '" + dir + "': " + ec.message() + "; choose a writable output path");
  const std::string probe = (dir.empty() ? std::string(".") : dir);
  if (access(probe.c_str(), W_OK) != 0)
    throw OutputError("folder '" + probe + "' is not writable; choose a writable output path");
}

AtomicOutput::AtomicOutput(std::string final_path) : final_(std::move(final_path)) {
  ensure_writable_directory(fs::path(final_).parent_path().string());
  temp_ = temp_name_beside(final_);
  slot_ = register_temp(temp_);
}

AtomicOutput::~AtomicOutput() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
  unregister_temp(slot_);
}

void AtomicOutput::commit() {
  std::error_code ec;
  if (!fs::exists(temp_, ec)) throw OutputError("writing '" + final_ + "' produced no file");
  fs::rename(temp_, final_, ec);
  if (ec) throw OutputError("cannot move the output into place at '" + final_ + "': " + ec.message());
  committed_ = true;
}

ReplaceableFolder folder_of_entries(std::function<bool(const std::string& name)> ours, std::string description) {
  return {[ours = std::move(ours)](const fs::path& folder) {
            std::error_code ec;
            if (!fs::is_directory(folder, ec)) return false;
            fs::directory_iterator it(folder, ec);
            if (ec) return false;
            for (const fs::directory_entry& e : it)
              if (!ours(e.path().filename().string())) return false;
            return true;
          },
          std::move(description)};
}

void require_replaceable(const std::string& path, const ReplaceableFolder& replaceable) {
  std::error_code ec;
  if (fs::exists(path, ec) && !replaceable.test(path))
    throw OutputError("'" + path + "' exists and is not " + replaceable.description +
                      "; choose another output folder, or move it away");
}

AtomicDirectory::AtomicDirectory(std::string final_path, ReplaceableFolder replaceable)
    : final_(std::move(final_path)), replaceable_(std::move(replaceable)) {
  while (!final_.empty() && final_.back() == '/') final_.pop_back();
  require_replaceable(final_, replaceable_);
  ensure_writable_directory(fs::path(final_).parent_path().string());
  temp_ = temp_name_beside(final_);
  slot_ = register_temp(temp_);
  std::error_code ec;
  fs::create_directories(temp_, ec);
  if (ec) throw OutputError("cannot create folder '" + temp_ + "': " + ec.message());
}

AtomicDirectory::~AtomicDirectory() {
  if (!committed_) {
    std::error_code ec;
    fs::remove_all(temp_, ec);
  }
  unregister_temp(slot_);
}

void AtomicDirectory::commit() {
  std::error_code ec;
  // A folder cannot be renamed over a non-empty one: move the old one aside first, and
  // only delete it once the new one is in place.
  std::string old;
  if (fs::exists(final_, ec)) {
    old = temp_name_beside(final_ + ".old");
    fs::rename(final_, old, ec);
    if (ec) throw OutputError("cannot replace the existing '" + final_ + "': " + ec.message());
    // Checked again once aside: something may have been put there since the start.
    if (!replaceable_.test(old)) {
      fs::rename(old, final_, ec);
      throw OutputError("'" + final_ + "' changed while mrsnake was writing and is not " + replaceable_.description +
                        " any more; the new output was not put in place");
    }
  }
  fs::rename(temp_, final_, ec);
  if (ec) {
    if (!old.empty()) fs::rename(old, final_, ec);
    throw OutputError("cannot move the output folder into place at '" + final_ + "'");
  }
  committed_ = true;
  if (!old.empty()) fs::remove_all(old, ec);
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
