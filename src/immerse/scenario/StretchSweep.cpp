#include "immerse/scenario/StretchSweep.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "immerse/core/Error.hpp"

namespace immerse {

StretchSweep::StretchSweep(const Simulation& sim) {
  const auto& c = sim.config();
  for (double f : c.get<std::vector<double>>("scenario.forces_pN")) forces_.push_back(f * 1e-12);
  require(!forces_.empty(), "scenario.forces_pN", "a non-empty list of forces");
  tol_ = c.get<double>("scenario.steady_tol");
  max_wait_ = c.get<double>("scenario.max_relaxation_times");
  t_relax_ = c.get<double>("fluid.mu") * c.get<double>("membrane[0].R0") / c.get<double>("scenario.mu0");
  const auto& ref = sim.reference(0);
  nodes_ = ref.size();
  auto lo = std::min_element(ref.begin(), ref.end(), [](const Vec3& a, const Vec3& b) { return a.x < b.x; });
  auto hi = std::max_element(ref.begin(), ref.end(), [](const Vec3& a, const Vec3& b) { return a.x < b.x; });
  const double r = 0.5 * c.get<double>("scenario.patch_um") * 1e-6;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    if (norm(ref[i] - *lo) <= r) left_.push_back(i);
    if (norm(ref[i] - *hi) <= r) right_.push_back(i);
  }
  if (left_.empty() || right_.empty())
    throw InputError("scenario.patch_um = " + std::to_string(2e6 * r) + ": the contact patches hold no mesh node");
  const bool shared = std::any_of(left_.begin(), left_.end(), [&](std::size_t i) { return norm(ref[i] - *hi) <= r; });
  if (shared || 2 * (left_.size() + right_.size()) > nodes_) {
    std::ostringstream s;
    s << "scenario.patch_um = " << 2e6 * r << ": the contact patches at the two ends of the cell's diameter along x ("
      << (hi->x - lo->x) * 1e6 << " um) "
      << (shared ? "share nodes" : "cover " + std::to_string(left_.size() + right_.size()) + " of its " +
                                       std::to_string(nodes_) + " nodes, more than half")
      << ": must be well below the diameter";
    throw InputError(s.str());
  }
}

std::vector<Vec3> StretchSweep::nodal_loads(double F) const {
  std::vector<Vec3> load(nodes_);
  for (auto i : left_) load[i] = {-F / double(left_.size()), 0, 0};
  for (auto i : right_) load[i] = {F / double(right_.size()), 0, 0};
  return load;
}

void StretchSweep::start(Simulation& sim, std::size_t index) {
  current_ = index;
  if (done()) return;
  sim.set_applied_forces(0, nodal_loads(forces_[index]));
  t_start_ = t_last_ = sim.time();
  last_ = cell_diameters(sim.op().membrane_positions(0), 0);
}

void StretchSweep::save(io::Checkpoint& ck) const {
  ck.put_int("sweep.current", static_cast<std::int64_t>(current_));
  ck.put_double("sweep.t_start", t_start_);
  ck.put_double("sweep.t_last", t_last_);
  ck.put_array("sweep.last_diameters", {last_.axial, last_.transverse});
}

void StretchSweep::restore(const io::Checkpoint& ck, Simulation& sim) {
  const auto index = ck.get_int("sweep.current");
  if (index < 0 || static_cast<std::size_t>(index) > forces_.size())
    throw InputError("checkpoint: force sweep position " + std::to_string(index) + " is outside scenario.forces_pN (" +
                     std::to_string(forces_.size()) + " forces)");
  current_ = static_cast<std::size_t>(index);
  if (!done()) sim.set_applied_forces(0, nodal_loads(forces_[current_]));
  t_start_ = ck.get_double("sweep.t_start");
  t_last_ = ck.get_double("sweep.t_last");
  const auto& d = ck.array("sweep.last_diameters");
  if (d.size() != 2) throw InputError("checkpoint: sweep.last_diameters must hold 2 numbers");
  last_ = {d[0], d[1]};
}

bool StretchSweep::steady(const Simulation& sim) {
  if (sim.time() - t_last_ < t_relax_) return false;
  const CellDiameters d = cell_diameters(sim.op().membrane_positions(0), 0);
  const bool still = std::abs(d.axial - last_.axial) <= tol_ * last_.axial &&
                     std::abs(d.transverse - last_.transverse) <= tol_ * last_.transverse;
  last_ = d;
  t_last_ = sim.time();
  return still;
}

bool StretchSweep::timed_out(const Simulation& sim) const { return sim.time() - t_start_ > max_wait_ * t_relax_; }

}  // namespace immerse
