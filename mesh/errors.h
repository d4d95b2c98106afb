#pragma once
/// \file errors.h
/// Small exception classes (pmp-library style). Every error a user can cause derives from
/// `Error`, carries a one-line message that says what is wrong and what to do, and maps to a
/// documented exit code of the `mrsnake` command.
#include <stdexcept>
#include <string>

namespace mrsnake {

/// Exit codes of the `mrsnake` command (documented in docs/exit-codes.md).
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

/// Base class of all mrsnake errors.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what, ExitCode code = ExitCode::internal) : std::runtime_error(what), code_(code) {}
  ExitCode code() const { return code_; }

 private:
  ExitCode code_;
};

/// An input file is missing, unreadable, corrupt or of an unsupported format.
class InputError : public Error {
 public:
  explicit InputError(const std::string& what) : Error(what, ExitCode::bad_input) {}
};

/// A mesh has a topology the algorithm does not accept (genus, boundaries, non-manifold...).
class TopologyError : public Error {
 public:
  explicit TopologyError(const std::string& what) : Error(what, ExitCode::bad_input) {}
};

/// An output could not be written.
class OutputError : public Error {
 public:
  explicit OutputError(const std::string& what) : Error(what, ExitCode::output) {}
};

/// Valid input on which an algorithm could not produce a valid result (solver failure,
/// extreme distortion...). Nothing is written when this is thrown.
class AlgorithmError : public Error {
 public:
  explicit AlgorithmError(const std::string& what) : Error(what, ExitCode::failed) {}
};

/// A batch ran to its end, but some items failed; the batch's summary lists them.
class PartialFailure : public Error {
 public:
  explicit PartialFailure(const std::string& what) : Error(what, ExitCode::some_failed) {}
};

}  // namespace mrsnake
