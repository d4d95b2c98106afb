#pragma once
/// \file hints.h
/// What to type about an error: the command line words each Remedy (mesh/errors.h) with the
/// flags of the command that met it.
#include <string>

#include "mesh/errors.h"

namespace mrsnake::cli {

/// The remedy of `error` in the words of `command` (e.g. "choose one of those with --label"),
/// or "" when it has none.
std::string hint_for(const Error& error, const std::string& command);

/// error.what(), followed by "; " and its hint when it has one.
std::string message_with_hint(const Error& error, const std::string& command);

}  // namespace mrsnake::cli
