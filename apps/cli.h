#pragma once
/// \file cli.h
/// What the subcommands share: registration, terminal progress and JSON output.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <iosfwd>
#include <string>

#include "mesh/progress.h"

namespace mrsnake {
enum class SphereMap;  // remesh/parameterization.h
}  // namespace mrsnake

namespace mrsnake::cli {

/// Options every command has.
struct GlobalOptions {
  bool quiet = false;  ///< no progress and no informational messages
};
GlobalOptions& global_options();

/// Progress drawn on stderr: a live line on a terminal, plain lines per stage otherwise,
/// nothing with --quiet.
ProgressFn terminal_progress();

/// Informational message on stderr, unless --quiet.
void info(const std::string& message);
/// Warning on stderr (shown even with --quiet).
void warn(const std::string& message);

/// Prints JSON (pretty) to stdout.
void print_json(const nlohmann::json& j);

// One registration function per subcommand (apps/cmd_*.cpp).
void add_info_command(CLI::App& app);
void add_model_info_command(CLI::App& app);
void add_quality_command(CLI::App& app);
void add_mc_command(CLI::App& app);
void add_synth_command(CLI::App& app);
void add_evaluate_command(CLI::App& app);
void add_remesh_command(CLI::App& app);
void add_build_model_command(CLI::App& app);
void add_segment_command(CLI::App& app);
void add_segment_batch_command(CLI::App& app);

/// Adds --sphere-map auto|halves|punctured (remesh), bound to `map`.
void add_sphere_map_option(CLI::App& command, SphereMap& map);

/// Adds --fit-rounds N (remesh), bound to `rounds` (RemeshOptions::fit.rounds);
/// its current value is the default the help shows.
void add_fit_rounds_option(CLI::App& command, int& rounds);

/// Makes every FLOAT option of app and its subcommands refuse nan and inf with a usage error
/// (CLI11's Range lets nan through: every comparison with it is false). Call after the
/// commands are added.
void refuse_non_finite_numbers(CLI::App& app);

}  // namespace mrsnake::cli
