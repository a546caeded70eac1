#include "immerse/core/Error.hpp"

#include <sstream>

namespace immerse {

namespace {
std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}
}  // namespace

InputError::InputError(const std::string& what) : std::runtime_error(one_line(what)) {}

void require(bool ok, const std::string& name, double value, const std::string& allowed) {
  if (ok) return;
  std::ostringstream s;
  s.precision(17);
  s << name << " = " << value << ": must be " << allowed;
  throw InputError(s.str());
}

void require(bool ok, const std::string& name, const std::string& allowed) {
  if (!ok) throw InputError(name + ": must be " + allowed);
}

}  // namespace immerse
