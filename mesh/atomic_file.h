#pragma once
/// \file atomic_file.h
/// Outputs are written to a temporary name in the same folder and renamed into place, so a
/// crash or an interrupt never leaves a half-written file under the final name.
#include <filesystem>
#include <functional>
#include <string>

namespace mrsnake {

/// A file being written. Write to temp_path(), then call commit(); if commit() is never
/// called the temporary is removed on destruction.
class AtomicOutput {
 public:
  /// \throw OutputError if the parent folder does not exist and cannot be created.
  explicit AtomicOutput(std::string final_path);
  ~AtomicOutput();
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  /// Temporary path: same folder and same extension(s) as the final path, so that writers
  /// that pick the format from the extension still work.
  const std::string& temp_path() const { return temp_; }
  const std::string& final_path() const { return final_; }
  /// Renames the temporary to the final path.
  /// \throw OutputError if the temporary is missing or the rename fails.
  void commit();

 private:
  std::string final_;
  std::string temp_;
  bool committed_ = false;
  int slot_ = -1;  ///< entry in the interrupt-cleanup table
};

/// Installs SIGINT/SIGTERM handlers that remove every live temporary (files and folders of
/// AtomicOutput and AtomicDirectory) and then exit with 128 + the signal number. Call once
/// from main.
void install_interrupt_cleanup();

/// Which existing folder an output may replace: an earlier result of the same command, never
/// other data (an input folder, a user's project). Given the folder, true if it may go.
struct ReplaceableFolder {
  std::function<bool(const std::filesystem::path& folder)> test;
  std::string description;  ///< what it is, for the error: "an output of mrsnake segment"
};

/// An empty folder, or one whose every entry's name satisfies `ours` (the names the command
/// writes), described as `description`.
ReplaceableFolder folder_of_entries(std::function<bool(const std::string& name)> ours, std::string description);

/// \throw OutputError if `path` exists and is not a folder that `replaceable` accepts.
void require_replaceable(const std::string& path, const ReplaceableFolder& replaceable);

/// A folder being written (e.g. a model): fill temp_path(), then commit() renames it to
/// the final path, replacing an existing folder of that name if `replaceable` accepts it, at
/// construction and again at the commit (the folder may have changed meanwhile). Removed if
/// never committed.
class AtomicDirectory {
 public:
  /// \throw OutputError if the parent folder cannot be created or written, or the final
  ///        path holds something `replaceable` refuses.
  AtomicDirectory(std::string final_path, ReplaceableFolder replaceable);
  ~AtomicDirectory();
  AtomicDirectory(const AtomicDirectory&) = delete;
  AtomicDirectory& operator=(const AtomicDirectory&) = delete;

  const std::string& temp_path() const { return temp_; }
  const std::string& final_path() const { return final_; }
  /// \throw OutputError if the rename fails, or the folder to replace no longer passes.
  void commit();

 private:
  std::string final_;
  std::string temp_;
  ReplaceableFolder replaceable_;
  bool committed_ = false;
  int slot_ = -1;  ///< entry in the interrupt-cleanup table
};

/// Writes a whole text file atomically.
/// \throw OutputError if it cannot be written.
void write_text_file_atomically(const std::string& path, const std::string& text);

/// Creates a folder (and its parents) if needed.
/// \throw OutputError if it cannot be created or is not writable.
void ensure_writable_directory(const std::string& dir);

}  // namespace mrsnake
