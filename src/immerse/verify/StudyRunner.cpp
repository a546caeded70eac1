#include "immerse/verify/StudyRunner.hpp"

#include <chrono>
#include <iomanip>
#include <ostream>

#include "immerse/core/Error.hpp"

namespace immerse::verify {

Study find_study(const std::string& name) {
  std::string known;
  for (auto& s : all_studies()) {
    if (s.name == name) return s;
    known += (known.empty() ? "" : ", ") + s.name;
  }
  throw InputError("verify: unknown study '" + name + "'; known studies: " + known);
}

bool run_study(const Study& study, bool quick, std::ostream& out) {
  out << "== " << study.name << (quick ? " (quick)" : "") << ": " << study.description << "\n";
  const auto t0 = std::chrono::steady_clock::now();
  const auto checks = study.run(quick);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  bool all = !checks.empty();
  for (const auto& c : checks) {
    out << "  " << (c.pass() ? "PASS" : "FAIL") << "  " << std::left << std::setw(58) << c.what << std::right
        << " measured " << std::setw(12) << std::setprecision(4) << std::scientific << c.measured << "  "
        << c.relation << " " << std::setw(10) << std::setprecision(3) << c.expected << std::defaultfloat << "\n";
    all = all && c.pass();
  }
  out << "  " << (all ? "PASS" : "FAIL") << " " << study.name << " (" << checks.size() << " checks, "
      << std::fixed << std::setprecision(1) << secs << " s)" << std::defaultfloat << "\n";
  return all;
}

void list_studies(std::ostream& out) {
  out << "Verification studies (run one with: immerse verify NAME [--quick]; 'all' runs every study):\n";
  for (const auto& s : all_studies()) out << "  " << std::left << std::setw(28) << s.name << s.description << "\n";
}

}  // namespace immerse::verify
