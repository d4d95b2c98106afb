// mrsnake: multiresolution snake segmentation with a prior shape model.
#include <vtkObject.h>

#include <iostream>

#include "apps/cli.h"
#include "apps/exit_codes.h"
#include "apps/hints.h"
#include "mesh/atomic_file.h"
#include "mesh/errors.h"

int main(int argc, char** argv) {
  using namespace mrsnake;
  // VTK would print its own multi-line errors for bad files; mrsnake reports them itself.
  vtkObject::GlobalWarningDisplayOff();
  install_interrupt_cleanup();

  CLI::App app{"mrsnake: fast 3D organ segmentation with a multiresolution snake and a prior shape model", "mrsnake"};
  app.set_version_flag("--version", std::string("mrsnake ") + MRSNAKE_VERSION);
  app.require_subcommand(1);
  app.fallthrough();
  app.add_flag("-q,--quiet", cli::global_options().quiet, "No progress or informational messages");
  app.footer("Run 'mrsnake <command> --help' for a command's options and an example.");

  cli::add_info_command(app);
  cli::add_model_info_command(app);
  cli::add_quality_command(app);
  cli::add_mc_command(app);
  cli::add_synth_command(app);
  cli::add_evaluate_command(app);
  cli::add_remesh_command(app);
  cli::add_build_model_command(app);
  cli::add_segment_command(app);
  cli::add_segment_batch_command(app);
  cli::refuse_non_finite_numbers(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : static_cast<int>(cli::ExitCode::usage);
  } catch (const Error& e) {
    const auto commands = app.get_subcommands();
    std::cerr << "mrsnake: error: " << cli::message_with_hint(e, commands.empty() ? "" : commands[0]->get_name())
              << '\n';
    return static_cast<int>(cli::exit_code_of(e));
  } catch (const std::bad_alloc&) {
    std::cerr << "mrsnake: error: out of memory; try a smaller input or fewer levels\n";
    return static_cast<int>(cli::ExitCode::failed);
  } catch (const std::exception& e) {
    std::cerr << "mrsnake: internal error: " << e.what() << " (please report this)\n";
    return static_cast<int>(cli::ExitCode::internal);
  }
  return 0;
}
