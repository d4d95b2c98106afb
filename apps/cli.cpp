#include "apps/cli.h"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <iostream>
#include <map>

#include "mesh/json_text.h"
#include "remesh/parameterization.h"

namespace mrsnake::cli {

GlobalOptions& global_options() {
  static GlobalOptions options;
  return options;
}

void info(const std::string& message) {
  if (!global_options().quiet) std::cerr << message << '\n';
}

void warn(const std::string& message) { std::cerr << "mrsnake: warning: " << message << '\n'; }

void print_json(const nlohmann::json& j) { std::cout << json_text(j, 2) << std::endl; }

void add_sphere_map_option(CLI::App& command, SphereMap& map) {
  command
      .add_option(
          "--sphere-map", map,
          "Closed surfaces: 'auto' (the default: halves from " +
              std::to_string(ParameterizationOptions{}.halves_from_faces) +
              " faces, punctured below, hierarchical where those fail), 'halves' (cut in two disks across a "
              "principal plane, one solve per core), 'punctured' (one vertex removed, one solve) or 'hierarchical' "
              "(coarse to fine from a tetrahedron: long protrusions keep their area); the options file's names "
              "'automatic' and 'two_halves' are taken too")
      ->transform(CLI::CheckedTransformer(std::map<std::string, SphereMap>{{"auto", SphereMap::automatic},
                                                                           {"automatic", SphereMap::automatic},
                                                                           {"halves", SphereMap::two_halves},
                                                                           {"two_halves", SphereMap::two_halves},
                                                                           {"punctured", SphereMap::punctured},
                                                                           {"hierarchical", SphereMap::hierarchical}}))
      ->option_text("auto|halves|punctured|hierarchical");
}

void add_fit_rounds_option(CLI::App& command, int& rounds) {
  command
      .add_option(
          "--fit-rounds", rounds,
          "Rounds of the least-squares fit of the finest level to the input along the vertex normals (default " +
              std::to_string(rounds) + "; 0 = off; the full method only, not with --strict or --no-relax)")
      ->check(CLI::Range(0, 100));
}

void refuse_non_finite_numbers(CLI::App& app) {
  const CLI::Validator finite(
      [](std::string& text) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (end != text.c_str() && !std::isfinite(value)) return "needs a finite number, not '" + text + "'";
        return {};
      },
      "", "finite");
  for (CLI::Option* option : app.get_options())
    if (option->get_type_name().rfind("FLOAT", 0) == 0) option->check(finite);
  for (CLI::App* command : app.get_subcommands([](CLI::App*) { return true; })) refuse_non_finite_numbers(*command);
}

ProgressFn terminal_progress() {
  if (global_options().quiet) return {};
  const bool tty = isatty(STDERR_FILENO) != 0;
  struct State {
    std::string stage;
    int percent = -1;
    std::chrono::steady_clock::time_point last{};
  };
  auto state = std::make_shared<State>();
  return [tty, state](const std::string& stage, double fraction) {
    const int percent = static_cast<int>(fraction * 100.0 + 0.5);
    if (tty) {
      const auto now = std::chrono::steady_clock::now();
      // Redraw at most every 50 ms, and always at a stage's start and end.
      if (stage == state->stage && percent == state->percent) return;
      if (stage == state->stage && percent < 100 && now - state->last < std::chrono::milliseconds(50)) return;
      state->last = now;
      std::fprintf(stderr, "\r\033[K%s %3d%%", stage.c_str(), percent);
      if (percent >= 100) std::fputc('\n', stderr);
      std::fflush(stderr);
    } else if (stage != state->stage) {
      std::fprintf(stderr, "%s...\n", stage.c_str());
    }
    state->stage = stage;
    state->percent = percent;
  };
}

}  // namespace mrsnake::cli
