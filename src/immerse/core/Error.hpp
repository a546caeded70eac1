#pragma once
// Error types. Every message is one line that names the offending key or item,
// what was given and what is allowed.
#include <stdexcept>
#include <string>

namespace immerse {

/// Bad user input (configuration, mesh, parameters, command line). Exit code 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A simulation that cannot go on (instability, inverted element, non-finite values).
class SimulationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws InputError("<name> = <value>: must be <allowed>") unless ok.
void require(bool ok, const std::string& name, double value, const std::string& allowed);
/// Throws InputError("<name>: must be <allowed>") unless ok.
void require(bool ok, const std::string& name, const std::string& allowed);

}  // namespace immerse
