#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>

#include "mesh/atomic_file.h"
#include "mesh/errors.h"
#include "tests/test_support.h"

using namespace mrsnake;
namespace fs = std::filesystem;

namespace {
int count_entries(const fs::path& dir) {
  int n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}
}  // namespace

TEST(AtomicFile, NothingUnderTheFinalNameUntilCommit) {
  const auto dir = test::scratch_dir("atomic");
  const auto final_path = dir / "out.txt";
  {
    AtomicOutput out(final_path.string());
    std::ofstream(out.temp_path()) << "partial";
    EXPECT_FALSE(fs::exists(final_path));
    EXPECT_EQ(fs::path(out.temp_path()).extension(), ".txt") << "writers pick formats by extension";
  }  // destroyed without commit: the temporary goes away
  EXPECT_EQ(count_entries(dir), 0);
  write_text_file_atomically(final_path.string(), "done");
  EXPECT_TRUE(fs::exists(final_path));
  EXPECT_EQ(count_entries(dir), 1);
}

// A command's output folder holds .txt files only, here.
const ReplaceableFolder text_files =
    folder_of_entries([](const std::string& name) { return fs::path(name).extension() == ".txt"; }, "a folder of text");

TEST(AtomicFile, DirectoryReplacesAnOldOneOnlyOnCommit) {
  const auto dir = test::scratch_dir("atomic-dir");
  const auto model = dir / "model";
  fs::create_directories(model);
  std::ofstream((model / "old.txt").string()) << "old";
  {
    AtomicDirectory out(model.string(), text_files);
    std::ofstream((fs::path(out.temp_path()) / "new.txt").string()) << "new";
    EXPECT_TRUE(fs::exists(model / "old.txt"));
    out.commit();
  }
  EXPECT_TRUE(fs::exists(model / "new.txt"));
  EXPECT_FALSE(fs::exists(model / "old.txt"));
  EXPECT_EQ(count_entries(dir), 1);
}

TEST(AtomicFile, UnwritableFolderIsAnOutputError) {
  // A folder under a regular file cannot be created, even by root.
  const auto dir = test::scratch_dir("atomic-bad");
  std::ofstream((dir / "file").string()) << "x";
  EXPECT_THROW(AtomicOutput((dir / "file" / "sub" / "x.txt").string()), OutputError);
  EXPECT_THROW(AtomicDirectory((dir / "file" / "model").string(), text_files), OutputError);
}

TEST(AtomicFile, DirectoryNeverReplacesOtherData) {
  const auto dir = test::scratch_dir("atomic-other");
  const auto out_path = dir / "out";
  fs::create_directories(out_path);
  std::ofstream((out_path / "thesis.tex").string()) << "precious";
  // Refused at the start: the folder holds something the command does not write.
  try {
    AtomicDirectory out(out_path.string(), text_files);
    ADD_FAILURE() << "a folder of other data was accepted";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("exists and is not a folder of text; choose another output folder"),
              std::string::npos)
        << e.what();
  }
  // Refused at the commit when other data arrives while the output is written.
  fs::remove(out_path / "thesis.tex");
  std::ofstream((out_path / "old.txt").string()) << "old";
  {
    AtomicDirectory out(out_path.string(), text_files);
    std::ofstream((fs::path(out.temp_path()) / "new.txt").string()) << "new";
    std::ofstream((out_path / "notes.md").string()) << "written meanwhile";
    EXPECT_THROW(out.commit(), OutputError);
  }
  EXPECT_TRUE(fs::exists(out_path / "notes.md"));
  EXPECT_TRUE(fs::exists(out_path / "old.txt"));
  EXPECT_FALSE(fs::exists(out_path / "new.txt"));
  EXPECT_EQ(count_entries(dir), 1) << "the new output's temporary or the moved-aside folder survived";
  // A file where the folder should go is refused too; an empty folder is replaced.
  std::ofstream((dir / "plain").string()) << "x";
  EXPECT_THROW(AtomicDirectory((dir / "plain").string(), text_files), OutputError);
  fs::create_directories(dir / "empty");
  AtomicDirectory empty((dir / "empty").string(), text_files);
  empty.commit();
}

TEST(AtomicFile, InterruptRemovesLiveTemporaries) {
  const auto dir = test::scratch_dir("atomic-signal");
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    install_interrupt_cleanup();
    AtomicOutput file((dir / "labels.nii.gz").string());
    std::ofstream(file.temp_path()) << "half written";
    AtomicDirectory folder((dir / "model").string(), text_files);
    std::ofstream((fs::path(folder.temp_path()) / "part.bin").string()) << "half written";
    raise(SIGTERM);
    _exit(0);  // not reached
  }
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM);
  EXPECT_EQ(count_entries(dir), 0) << "a temporary survived the interrupt";
}
