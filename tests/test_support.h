#pragma once
// Shared helpers for the GoogleTest suites: the shared data folder and running the CLI.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace mrsnake::test {

/// The folder of real test data: $MRSNAKE_DATA, else ../shared/data beside the project.
inline std::filesystem::path data_dir() {
  if (const char* env = std::getenv("MRSNAKE_DATA"); env && *env) return env;
  return std::filesystem::path(MRSNAKE_SOURCE_DIR) / ".." / "shared" / "data";
}

/// Path of a data file, or empty if the data folder or the file is absent.
inline std::string data_file(const std::string& relative) {
  const auto p = data_dir() / relative;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

/// A fresh scratch folder for one test.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("mrsnake-test-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// Every byte of a file (empty if it cannot be read), for tests that damage files on purpose.
inline std::vector<std::uint8_t> read_all(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Replaces a file's bytes.
inline void write_all(const std::filesystem::path& p, const std::vector<std::uint8_t>& b) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

struct CommandResult {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr together
};

/// The longest one command of a test may run: a command that hangs fails its test with its
/// own output, instead of stalling the test until ctest's timeout with none.
constexpr int kCommandTimeoutSeconds = 600;

/// Runs the mrsnake executable (its path is in $MRSNAKE_BIN, set by ctest) with arguments,
/// stopped after kCommandTimeoutSeconds (exit code 124, and a line saying so).
inline CommandResult run_mrsnake(const std::string& args) {
  const char* bin = std::getenv("MRSNAKE_BIN");
  CommandResult r;
  if (!bin) {
    r.output = "MRSNAKE_BIN is not set; run the tests through ctest";
    return r;
  }
  const std::string cmd =
      "timeout -k 10 " + std::to_string(kCommandTimeoutSeconds) + " " + std::string(bin) + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), static_cast<int>(buf.size()), pipe)) r.output += buf.data();
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (r.exit_code == 124)
    r.output += "\n(mrsnake " + args + " did not end within " + std::to_string(kCommandTimeoutSeconds) +
                " s and was stopped)\n";
  return r;
}

}  // namespace mrsnake::test

/// Skips the test with a clear message when a shared data file is absent.
#define MRSNAKE_REQUIRE_DATA(var, relative)                                                               \
  const std::string var = ::mrsnake::test::data_file(relative);                                           \
  if (var.empty())                                                                                        \
  GTEST_SKIP() << "shared data file '" << relative << "' not found under " << ::mrsnake::test::data_dir() \
               << " (set MRSNAKE_DATA to the shared data folder)"
