#pragma once
/// \file atomic_file.h
/// Outputs are written to a temporary name in the same folder and renamed into place, so a
/// crash or an interrupt never leaves a half-written file under the final name.
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

/// A folder being written (e.g. a model): fill temp_path(), then commit() renames it to
/// the final path, replacing an existing folder of that name. Removed if never committed.
class AtomicDirectory {
 public:
  /// \throw OutputError if the parent folder cannot be created or written.
  explicit AtomicDirectory(std::string final_path);
  ~AtomicDirectory();
  AtomicDirectory(const AtomicDirectory&) = delete;
  AtomicDirectory& operator=(const AtomicDirectory&) = delete;

  const std::string& temp_path() const { return temp_; }
  const std::string& final_path() const { return final_; }
  /// \throw OutputError if the rename fails.
  void commit();

 private:
  std::string final_;
  std::string temp_;
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
