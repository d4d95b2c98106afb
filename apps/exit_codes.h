#pragma once
/// \file exit_codes.h
/// Exit codes of the `mrsnake` command (documented in docs/exit-codes.md), and the code of
/// each error class of mesh/errors.h.
#include "mesh/errors.h"

namespace mrsnake::cli {

enum class ExitCode : int {
  success = 0,
  internal = 1,     ///< a bug: an unexpected exception
  usage = 2,        ///< bad command-line arguments
  bad_input = 3,    ///< an input file is missing, corrupt, unsupported or of the wrong kind
  output = 4,       ///< an output could not be written
  failed = 5,       ///< the algorithm could not produce a valid result from valid input
  some_failed = 6,  ///< a batch ran, but some of its items failed (each is listed with its error)
  interrupted = 130,
};

/// InputError and TopologyError: bad_input; OutputError: output; AlgorithmError: failed;
/// PartialFailure: some_failed; any other Error: internal.
ExitCode exit_code_of(const Error& error);

}  // namespace mrsnake::cli
