#pragma once
// Error types. Every message is one line that names the offending key or item,
// what was given and what is allowed.
#include <stdexcept>
#include <string>
#include <string_view>

namespace immerse {

/// Bad user input (configuration, mesh, parameters, command line). Exit code 2.
class InputError : public std::runtime_error {
 public:
  /// Line breaks in `what` (a quoted key, a file name or a value as given) become spaces: the message is one line.
  explicit InputError(const std::string& what);
};

/// A file that cannot be written (a missing or unwritable folder, a full disk): "cannot write <path>: <reason>".
/// Before a run starts it is bad input (exit 2); during a run it stops the run (exit 5), the files written
/// before it being complete (every write is atomic).
class WriteError : public InputError {
 public:
  using InputError::InputError;
};

/// A simulation that cannot go on (instability, inverted element, non-finite values).
class SimulationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A stop asked for (by a signal) while a rejected step was to be retried: the state is that of the last accepted
/// step, nothing of the retried one is committed.
class StopRequested : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// `text` as a message shows a value given: whole up to 80 characters, else its first 80 and "... (N characters)".
std::string echoed(std::string_view text);

/// Throws InputError("<name> = <value>: must be <allowed>") unless ok.
void require(bool ok, const std::string& name, double value, const std::string& allowed);
/// Throws InputError("<name>: must be <allowed>") unless ok.
void require(bool ok, const std::string& name, const std::string& allowed);

}  // namespace immerse
