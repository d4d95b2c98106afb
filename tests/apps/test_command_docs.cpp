// The reference pages of the commands (docs/commands/<command>.md) against the commands'
// --help: every subcommand has a page, every page a subcommand, and each page's Options table
// has one row per flag of the help's Options section, and no other.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/test_support.h"

using mrsnake::test::run_mrsnake;
namespace fs = std::filesystem;

namespace {

const fs::path kPages = fs::path(MRSNAKE_SOURCE_DIR) / "docs" / "commands";

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
  }
  return lines;
}

bool blank(const std::string& line) { return line.find_first_not_of(" \t") == std::string::npos; }

/// The lines of a CLI11 help section ("Options:", "Subcommands:"): from its heading to the
/// first blank line, after which the footer (examples, notes) begins.
std::vector<std::string> help_section(const std::string& help, const std::string& heading) {
  std::vector<std::string> section;
  bool inside = false;
  for (const std::string& line : lines_of(help)) {
    if (!inside) {
      inside = line == heading;
      continue;
    }
    if (blank(line)) break;
    section.push_back(line);
  }
  return section;
}

/// The first word of a line indented by two spaces: the names column of a help section
/// ("  -o,--output TEXT REQUIRED   Output folder" gives "-o,--output"). The continuation
/// lines of a description are indented further and give nothing.
std::string names_column(const std::string& line) {
  if (line.size() < 3 || line.compare(0, 2, "  ") != 0 || line[2] == ' ') return {};
  const std::size_t end = line.find(' ', 2);
  return line.substr(2, end == std::string::npos ? std::string::npos : end - 2);
}

/// Every `--flag` in a piece of text.
std::vector<std::string> long_flags(const std::string& text) {
  static const std::regex flag("--[a-z][a-z0-9-]*");
  std::vector<std::string> flags;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), flag); it != std::sregex_iterator(); ++it)
    flags.push_back(it->str());
  return flags;
}

/// The subcommands that `mrsnake --help` lists.
std::vector<std::string> subcommands(std::string& failure) {
  const auto r = run_mrsnake("--help");
  if (r.exit_code != 0) {
    failure = "'mrsnake --help' exited with " + std::to_string(r.exit_code) + ":\n" + r.output;
    return {};
  }
  std::vector<std::string> names;
  for (const std::string& line : help_section(r.output, "Subcommands:"))
    if (const std::string name = names_column(line); !name.empty()) names.push_back(name);
  if (names.empty()) failure = "'mrsnake --help' lists no subcommands:\n" + r.output;
  return names;
}

/// The long flags that `mrsnake <command> --help` defines in its Options section (the names
/// column only: flags named inside a description, "Needs: --x" or "as 'build-model --x'",
/// belong to other options or commands).
std::set<std::string> help_flags(const std::string& command, std::string& failure) {
  const auto r = run_mrsnake(command + " --help");
  if (r.exit_code != 0) {
    failure = "'mrsnake " + command + " --help' exited with " + std::to_string(r.exit_code) + ":\n" + r.output;
    return {};
  }
  std::set<std::string> flags;
  for (const std::string& line : help_section(r.output, "Options:"))
    for (const std::string& flag : long_flags(names_column(line))) flags.insert(flag);
  if (flags.empty()) failure = "'mrsnake " + command + " --help' has no Options section with flags:\n" + r.output;
  return flags;
}

/// The cells of a Markdown table row ("| a | b \| c |" gives "a", "b \| c").
std::vector<std::string> cells(const std::string& row) {
  std::vector<std::string> out;
  std::string cell;
  for (std::size_t i = 1; i < row.size(); ++i) {
    if (row[i] == '|' && row[i - 1] != '\\') {
      out.push_back(cell);
      cell.clear();
    } else {
      cell += row[i];
    }
  }
  return out;
}

/// A page's Options table: for each `--flag` in the first cell of a row ("| " at the start)
/// of the section "## Options" (up to the next "## " heading), the rows that hold it.
std::map<std::string, int> page_flags(const fs::path& page, std::string& failure) {
  std::ifstream in(page);
  if (!in) {
    failure = "cannot read " + page.string();
    return {};
  }
  std::map<std::string, int> rows_of;
  bool inside = false, found = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("## ", 0) == 0) {
      inside = line == "## Options";
      found = found || inside;
      continue;
    }
    if (!inside || line.rfind("| ", 0) != 0) continue;
    const std::vector<std::string> row = cells(line);
    if (row.empty()) continue;
    std::set<std::string> in_row;
    for (const std::string& flag : long_flags(row[0])) in_row.insert(flag);
    for (const std::string& flag : in_row) ++rows_of[flag];
  }
  if (!found) failure = page.string() + " has no \"## Options\" section";
  return rows_of;
}

std::string page_of(const std::string& command) { return "docs/commands/" + command + ".md"; }

TEST(CommandDocs, EverySubcommandHasAPageAndEveryPageASubcommand) {
  std::string failure;
  const std::vector<std::string> commands = subcommands(failure);
  ASSERT_TRUE(failure.empty()) << failure;
  const std::set<std::string> listed(commands.begin(), commands.end());
  for (const std::string& command : commands)
    EXPECT_TRUE(fs::exists(kPages / (command + ".md")))
        << "'mrsnake " << command << "' has no reference page: write " << page_of(command)
        << " (its Options table lists every flag of 'mrsnake " << command << " --help')";
  ASSERT_TRUE(fs::is_directory(kPages)) << kPages << " is missing";
  for (const auto& entry : fs::directory_iterator(kPages)) {
    if (entry.path().extension() != ".md") continue;
    const std::string name = entry.path().stem().string();
    EXPECT_TRUE(listed.count(name) > 0) << page_of(name) << " documents '" << name
                                        << "', which 'mrsnake --help' does not list as a subcommand";
  }
}

TEST(CommandDocs, EveryHelpFlagHasOneRowInItsPagesOptionsTable) {
  std::string failure;
  const std::vector<std::string> commands = subcommands(failure);
  ASSERT_TRUE(failure.empty()) << failure;
  for (const std::string& command : commands) {
    const std::set<std::string> help = help_flags(command, failure);
    ASSERT_TRUE(failure.empty()) << failure;
    if (!fs::exists(kPages / (command + ".md"))) continue;  // the test above names it
    const std::map<std::string, int> page = page_flags(kPages / (command + ".md"), failure);
    ASSERT_TRUE(failure.empty()) << failure;
    for (const std::string& flag : help) {
      const auto it = page.find(flag);
      EXPECT_TRUE(it != page.end()) << "'mrsnake " << command << " --help' has " << flag
                                    << ", which the Options table of " << page_of(command) << " does not list";
      if (it != page.end()) {
        EXPECT_EQ(it->second, 1) << page_of(command) << " lists " << flag << " in " << it->second
                                 << " rows of its Options table; one row per flag";
      }
    }
  }
}

TEST(CommandDocs, EveryOptionsTableFlagIsInTheHelp) {
  std::string failure;
  const std::vector<std::string> commands = subcommands(failure);
  ASSERT_TRUE(failure.empty()) << failure;
  for (const std::string& command : commands) {
    if (!fs::exists(kPages / (command + ".md"))) continue;
    const std::set<std::string> help = help_flags(command, failure);
    ASSERT_TRUE(failure.empty()) << failure;
    const std::map<std::string, int> page = page_flags(kPages / (command + ".md"), failure);
    ASSERT_TRUE(failure.empty()) << failure;
    for (const auto& row : page)
      EXPECT_TRUE(help.count(row.first) > 0) << "the Options table of " << page_of(command) << " lists " << row.first
                                             << ", which 'mrsnake " << command << " --help' does not have";
  }
}

}  // namespace
