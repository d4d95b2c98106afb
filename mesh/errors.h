#pragma once
/// \file errors.h
/// Small exception classes (pmp-library style). Every error a user can cause derives from
/// `Error` and carries a one-line message that says what is wrong, and the remedy, if any, as
/// a value. The command line maps each class to an exit code (apps/exit_codes.h) and words the
/// remedy with its flags (apps/hints.h).
#include <stdexcept>
#include <string>

namespace mrsnake {

/// What would get the user past an error. A library error says what is wrong; the command
/// line words the remedy with its own flags (apps/hints.h).
enum class Remedy {
  none,
  choose_label,              ///< another label value, one of those present
  choose_component,          ///< another part of the label, 1 to Error::remedy_limit()
  other_resolution,          ///< another face count of the finest level
  other_initialization,      ///< another way of placing the model
  rebuild_model,             ///< the model is damaged or empty: build it again
  rebuild_model_with_image,  ///< a section that only a model built with an image has
  make_model,                ///< the folder is not a model: build one
  inspect_mesh,              ///< the mesh is malformed: look at it
};

/// Base class of all mrsnake errors.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what, Remedy remedy = Remedy::none, int remedy_limit = 0)
      : std::runtime_error(what), remedy_(remedy), remedy_limit_(remedy_limit) {}
  Remedy remedy() const { return remedy_; }
  /// The largest value the remedy can take (e.g. the number of parts), or 0.
  int remedy_limit() const { return remedy_limit_; }

 private:
  Remedy remedy_;
  int remedy_limit_;
};

/// An input file is missing, unreadable, corrupt or of an unsupported format.
class InputError : public Error {
 public:
  using Error::Error;
};

/// An option (a flag, or a key of an options file) has a value outside its range.
class OptionsError : public InputError {
 public:
  using InputError::InputError;
};

/// A mesh has a topology the algorithm does not accept (genus, boundaries, non-manifold...).
class TopologyError : public Error {
 public:
  using Error::Error;
};

/// An output could not be written.
class OutputError : public Error {
 public:
  using Error::Error;
};

/// Valid input on which an algorithm could not produce a valid result (solver failure,
/// extreme distortion...). Nothing is written when this is thrown.
class AlgorithmError : public Error {
 public:
  using Error::Error;
};

/// A batch ran to its end, but some items failed; the batch's summary lists them.
class PartialFailure : public Error {
 public:
  using Error::Error;
};

}  // namespace mrsnake
