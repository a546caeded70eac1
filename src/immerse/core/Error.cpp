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

std::string echoed(std::string_view text) {
  constexpr std::size_t kShown = 80;
  if (text.size() <= kShown) return std::string(text);
  return std::string(text.substr(0, kShown)) + "... (" + std::to_string(text.size()) + " characters)";
}

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
