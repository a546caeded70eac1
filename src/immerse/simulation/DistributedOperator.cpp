#include "immerse/simulation/DistributedOperator.hpp"

#include <mpi.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <optional>
#include <stdexcept>
#include <utility>

#include "immerse/core/Error.hpp"
#include "immerse/coupling/NodeDiagnostics.hpp"
#include "immerse/parallel/Agreement.hpp"
#include "immerse/simulation/InversionReport.hpp"
#include "immerse/timestep/LogEvent.hpp"

namespace immerse {

namespace {

std::span<const Vec3> nodes(std::span<const double> x) {
  return {reinterpret_cast<const Vec3*>(x.data()), x.size() / 3};
}

std::span<Vec3> nodes(std::span<double> x) { return {reinterpret_cast<Vec3*>(x.data()), x.size() / 3}; }

/// Whether any process reports `failed` (collective); the same answer on every process.
bool any_failed(const Communicator& comm, bool failed) { return comm.sum(failed ? 1.0 : 0.0) > 0; }

}  // namespace

DistributedOperator::DistributedOperator(SlabNavierStokesSolver& fluid, SlabIBCoupler& coupler,
                                         std::vector<const ElasticMembrane*> membranes,
                                         std::span<const std::vector<Vec3>> X0,
                                         std::span<const std::vector<Vec3>> reference, FluidState fluid_state,
                                         const ContactSettings& contact, std::vector<double> viscosity_ratio)
    : fluid_(fluid),
      coupler_(coupler),
      membranes_(std::move(membranes)),
      contact_(contact),
      ownership_(fluid.decomposition(), X0, reference),
      committed_(std::move(fluid_state)) {
  if (X0.size() != membranes_.size()) throw std::logic_error("DistributedOperator: one position array per membrane");
  for (std::size_t m = 0; m < membranes_.size(); ++m) {
    if (X0[m].size() != membranes_[m]->num_nodes())
      throw InputError("membrane[" + std::to_string(m) + "]: " + std::to_string(X0[m].size()) +
                       " initial positions for a mesh of " + std::to_string(membranes_[m]->num_nodes()) + " nodes");
    total_nodes_ += X0[m].size();
    moduli_.push_back(small_strain_area_modulus(membranes_[m]->law()));
  }
  if (contact_.range > 0)  // refuses a range of half a periodic length or more (InputError), on every process alike
    [[maybe_unused]] const ContactForce validated(fluid_.grid(), contact_, {0, total_nodes_}, {0.0});
  if (std::ranges::any_of(viscosity_ratio, [](double r) { return r != 1.0; })) {
    if (viscosity_ratio.size() != membranes_.size())
      throw std::logic_error("DistributedOperator: one viscosity ratio per membrane");
    if (!fluid_.params().variable_viscosity)
      throw std::logic_error("DistributedOperator: a viscosity contrast needs a fluid solver with variable viscosity");
    indicator_ = std::make_unique<SlabViscosityIndicator>(coupler_, std::move(viscosity_ratio));
  }
  refresh();
  U_.resize(X_.size());
  timed(timings_.interpolate, Phase::Interpolation, [&] { coupler_.interpolate_velocity(committed_.u, X_, U_); });
}

void DistributedOperator::update_indicator(std::span<const Vec3> Xf) {
  const auto& owned = ownership_.owned();
  Xmid_.resize(owned.size());
  std::vector<OwnedIndicatorSurface> surfaces;
  for (std::size_t k = 0; k < owned.size(); ++k) {
    const std::size_t n = offset_[k + 1] - offset_[k];
    Xmid_[k].resize(n);
    for (std::size_t i = 0; i < n; ++i) Xmid_[k][i] = 0.5 * (X_[offset_[k] + i] + Xf[offset_[k] + i]);
    surfaces.push_back({owned[k].id, &membranes_[static_cast<std::size_t>(owned[k].id)]->elements(), &Xmid_[k]});
  }
  indicator_->compute(surfaces, chi_);
}

void DistributedOperator::refresh() {
  X_ = ownership_.owned_positions();
  offset_.assign(1, 0);
  for (const OwnedMembrane& m : ownership_.owned()) offset_.push_back(offset_.back() + m.positions.size());
}

std::vector<std::size_t> DistributedOperator::membrane_offsets() const {
  std::vector<std::size_t> o(offset_.size());
  std::ranges::transform(offset_, o.begin(), [](std::size_t node) { return 3 * node; });
  return o;
}

void DistributedOperator::nodal_forces(std::span<const Vec3> Xf) {
  const auto& owned = ownership_.owned();
  F_.resize(Xf.size());
  Fm_.resize(owned.size());
  std::string error;
  std::size_t failed = owned.size();
  timed(timings_.force, Phase::MembraneForces, [&] {
    for (std::size_t k = 0; k < owned.size() && error.empty(); ++k) {
      const std::span<const Vec3> Xm = Xf.subspan(offset_[k], offset_[k + 1] - offset_[k]);
      try {
        check_nodes_in_domain(fluid_.grid(), Xm);
        membranes_[static_cast<std::size_t>(owned[k].id)]->compute_force(Xm, Fm_[k]);
      } catch (const SimulationError& e) {
        error = e.what();
        failed = k;
      }
      if (error.empty())
        std::copy(Fm_[k].begin(), Fm_[k].end(), F_.begin() + static_cast<std::ptrdiff_t>(offset_[k]));
    }
  });
  if (any_failed(fluid_.decomposition().communicator(), !error.empty()))
    throw SimulationError(failure_report(Xf, failed, error));
  // After the membranes, which have checked that every node is finite and inside the box.
  if (contact_.range > 0) timed(timings_.contact, Phase::Contact, [&] { add_contact_forces(Xf); });
}

// The lowest-ranked failing process's message on every process; for an inverted element, with where it stands, the
// nearest node of another membrane searched on every process (each over the membranes it owns).
std::string DistributedOperator::failure_report(std::span<const Vec3> Xf, std::size_t failed,
                                                const std::string& error) const {
  const Communicator& comm = fluid_.decomposition().communicator();
  const auto& owned = ownership_.owned();
  const std::optional<std::size_t> element = error.empty() ? std::nullopt : inverted_element(error);
  // Per process: whether it failed, then for an inversion the membrane, the element and its six nodes.
  constexpr std::size_t kRecord = 21;
  std::vector<double> mine(kRecord, 0.0);
  std::span<const Vec3> Xm;
  if (!error.empty()) {
    mine[0] = element ? 2 : 1;
    Xm = Xf.subspan(offset_[failed], offset_[failed + 1] - offset_[failed]);
  }
  if (element) {
    const auto id = static_cast<std::size_t>(owned[failed].id);
    mine[1] = static_cast<double>(id);
    mine[2] = static_cast<double>(*element);
    const auto nodes = nodes_of_element(*membranes_[id], Xm, *element);
    for (std::size_t i = 0; i < nodes.size(); ++i)
      for (int a = 0; a < 3; ++a) mine[3 + 3 * i + static_cast<std::size_t>(a)] = nodes[i][a];
  }
  const std::vector<double> all = comm.all_gather(mine);
  std::size_t first = 0;
  while (all[kRecord * first] == 0) ++first;  // a process failed: any_failed said so
  std::string details;
  if (all[kRecord * first] == 2) {
    const double* record = &all[kRecord * first];
    const auto id = static_cast<std::size_t>(record[1]), inverted = static_cast<std::size_t>(record[2]);
    std::array<Vec3, 6> nodes;
    for (std::size_t i = 0; i < nodes.size(); ++i) nodes[i] = {record[3 + 3 * i], record[4 + 3 * i], record[5 + 3 * i]};
    NearestMembrane nearest;
    for (std::size_t k = 0; k < owned.size(); ++k)
      if (static_cast<std::size_t>(owned[k].id) != id)
        nearest.consider(fluid_.grid(), nodes, Xf.subspan(offset_[k], offset_[k + 1] - offset_[k]),
                         static_cast<std::size_t>(owned[k].id));
    const std::vector<double> candidates =
        comm.all_gather(std::vector<double>{nearest.distance, static_cast<double>(nearest.membrane)});
    for (std::size_t p = 0; p < candidates.size(); p += 2)
      if (candidates[p] < nearest.distance ||
          (candidates[p] == nearest.distance && candidates[p + 1] < static_cast<double>(nearest.membrane)))
        nearest = {candidates[p], static_cast<std::size_t>(candidates[p + 1])};
    if (static_cast<std::size_t>(comm.rank()) == first)
      details = inversion_details(fluid_.grid(), *membranes_[id], Xm, inverted, nearest);
  }
  const std::string named = error.empty() ? error : "membrane[" + std::to_string(owned[failed].id) + "] " + error + details;
  return first_error(comm, named);
}

void DistributedOperator::add_contact_forces(std::span<const Vec3> Xf) {
  const Communicator& comm = fluid_.decomposition().communicator();
  const int rank = comm.rank(), size = comm.size();
  const auto& owned = ownership_.owned();
  const std::size_t M = membranes_.size();
  // Every membrane's bounds, from its owner: index, owner, centre, half-widths, radius.
  std::vector<double> mine;
  for (std::size_t k = 0; k < owned.size(); ++k) {
    const auto b = ContactForce::bounds(Xf.subspan(offset_[k], offset_[k + 1] - offset_[k]));
    mine.insert(mine.end(), {double(owned[k].id), double(rank), b.centre.x, b.centre.y, b.centre.z, b.half.x,
                             b.half.y, b.half.z, b.radius});
  }
  const std::vector<double> all = comm.all_gather(mine);
  std::vector<ContactForce::Bounds> box(M);
  std::vector<int> owner(M, -1);
  for (std::size_t q = 0; q + 9 <= all.size(); q += 9) {
    const auto m = static_cast<std::size_t>(all[q]);
    owner[m] = static_cast<int>(all[q + 1]);
    box[m] = {{all[q + 2], all[q + 3], all[q + 4]}, {all[q + 5], all[q + 6], all[q + 7]}, all[q + 8]};
  }
  const double d = contact_.range;
  const auto near = [&](std::size_t a, std::size_t b) {  // the serial broad phase, lower index first
    return ContactForce::boxes_within_range(fluid_.grid(), d, box[std::min(a, b)], box[std::max(a, b)]);
  };
  // What to send: each owned membrane to every other process owning a membrane near it, in ascending index.
  std::vector<std::vector<double>> out(static_cast<std::size_t>(size));
  for (std::size_t k = 0; k < owned.size(); ++k) {
    const auto b = static_cast<std::size_t>(owned[k].id);
    std::vector<char> to(static_cast<std::size_t>(size), 0);
    for (std::size_t a = 0; a < M; ++a)
      if (owner[a] != rank && a != b && near(a, b)) to[static_cast<std::size_t>(owner[a])] = 1;
    for (int r = 0; r < size; ++r) {
      if (!to[static_cast<std::size_t>(r)]) continue;
      std::vector<double>& o = out[static_cast<std::size_t>(r)];
      o.push_back(double(b));
      for (std::size_t i = offset_[k]; i < offset_[k + 1]; ++i) o.insert(o.end(), {Xf[i].x, Xf[i].y, Xf[i].z});
    }
  }
  std::vector<int> send_counts(size), send_offsets(size, 0), recv_counts(size), recv_offsets(size, 0);
  for (int r = 0; r < size; ++r) send_counts[r] = static_cast<int>(out[static_cast<std::size_t>(r)].size());
  check_mpi(MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, comm.comm()), "MPI_Alltoall");
  for (int r = 1; r < size; ++r) {
    send_offsets[r] = send_offsets[r - 1] + send_counts[r - 1];
    recv_offsets[r] = recv_offsets[r - 1] + recv_counts[r - 1];
  }
  std::vector<double> send, recv(static_cast<std::size_t>(recv_offsets[size - 1] + recv_counts[size - 1]));
  for (const auto& o : out) send.insert(send.end(), o.begin(), o.end());
  check_mpi(MPI_Alltoallv(send.data(), send_counts.data(), send_offsets.data(), MPI_DOUBLE, recv.data(),
                      recv_counts.data(), recv_offsets.data(), MPI_DOUBLE, comm.comm()),
        "MPI_Alltoallv");
  // The owned and the received membranes, concatenated in ascending global index.
  std::vector<std::pair<std::size_t, std::span<const Vec3>>> parts;
  for (std::size_t k = 0; k < owned.size(); ++k)
    parts.emplace_back(static_cast<std::size_t>(owned[k].id), Xf.subspan(offset_[k], offset_[k + 1] - offset_[k]));
  for (std::size_t q = 0; q < recv.size();) {
    const auto m = static_cast<std::size_t>(recv[q]);
    const std::size_t n = membranes_[m]->num_nodes();
    parts.emplace_back(m, std::span<const Vec3>(reinterpret_cast<const Vec3*>(recv.data() + q + 1), n));
    q += 1 + 3 * n;
  }
  std::ranges::sort(parts, {}, &std::pair<std::size_t, std::span<const Vec3>>::first);
  std::vector<Vec3> X;
  std::vector<std::size_t> offsets{0}, local(M, M);  // local: position of an owned membrane in parts
  std::vector<double> moduli;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    X.insert(X.end(), parts[p].second.begin(), parts[p].second.end());
    offsets.push_back(X.size());
    moduli.push_back(moduli_[parts[p].first]);
    local[parts[p].first] = p;
  }
  if (X.empty()) return;
  ContactForce contact(fluid_.grid(), contact_, offsets, std::move(moduli));
  contact.set_search_nodes(total_nodes_);
  std::vector<Vec3> F(X.size());
  contact.compute(X, F);
  for (std::size_t k = 0; k < owned.size(); ++k) {
    const std::size_t first = offsets[local[static_cast<std::size_t>(owned[k].id)]];
    for (std::size_t i = offset_[k]; i < offset_[k + 1]; ++i) F_[i] += F[first + (i - offset_[k])];
  }
}

template <class F>
void DistributedOperator::governed(F&& evaluation) {
  governor_.choose();
  const auto t0 = std::chrono::steady_clock::now();
  evaluation();
  governor_.record(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

void DistributedOperator::trial_step(std::span<const double> Xf, double theta, double dt) {
  trial_X_.clear();
  trial_done_ = false;
  if (theta < 1.0 && !start_valid_) {  // S(X^n) f(X^n), once per step unless the last trial left it
    nodal_forces(X_);
    timed(timings_.spread, Phase::Spreading, [&] { coupler_.spread_force(X_, F_, force_start_); });
    start_valid_ = true;
  }
  nodal_forces(nodes(Xf));
  timed(timings_.spread, Phase::Spreading, [&] { coupler_.spread_force(nodes(Xf), F_, force_); });
  if (theta < 1.0) {  // F^{n+1/2} = theta S(Xf) f(Xf) + (1 - theta) S(X^n) f(X^n), as ImmersedBoundaryOperator
    mixed_ = force_;
    for (int d = 0; d < 3; ++d) {
      auto& o = mixed_[d].values();
      const auto& x = force_[d].values();
      const auto& y = force_start_[d].values();
      for (std::size_t i = 0; i < o.size(); ++i) o[i] = theta * x[i] + (1.0 - theta) * y[i];
    }
  }
  timed(timings_.fluid, Phase::FluidStep, [&] {
    if (indicator_) update_indicator(nodes(Xf));
    fluid_.step(committed_, theta < 1.0 ? mixed_ : force_, dt, trial_, indicator_ ? &chi_ : nullptr);
  });
  ++solves_;
}

void DistributedOperator::trial_velocity(std::span<const double> Xf, double theta, std::span<const double> Xi,
                                         double dt, std::span<double> U) {
  governed([&] {
    trial_step(Xf, theta, dt);
    timed(timings_.interpolate, Phase::Interpolation,
          [&] { coupler_.interpolate_velocity(trial_.u, nodes(Xi), nodes(U)); });
  });
  trial_X_.assign(Xf.begin(), Xf.end());
  trial_done_ = true;
}

void DistributedOperator::trial_mean_velocity(std::span<const double> Xf, std::span<const double> Xi, double dt,
                                              std::span<double> U) {
  governed([&] {
    trial_step(Xf, 1.0, dt);
    // As ImmersedBoundaryOperator's blend with theta = 1/2, on every plane of the slabs.
    mean_ = trial_.u;
    for (int d = 0; d < 3; ++d) {
      auto& o = mean_[d].values();
      const auto& x = trial_.u[d].values();
      const auto& y = committed_.u[d].values();
      for (std::size_t i = 0; i < o.size(); ++i) o[i] = 0.5 * x[i] + 0.5 * y[i];
    }
    timed(timings_.interpolate, Phase::Interpolation,
          [&] { coupler_.interpolate_velocity(mean_, nodes(Xi), nodes(U)); });
  });
  trial_X_.assign(Xf.begin(), Xf.end());
  trial_done_ = true;
}

void DistributedOperator::committed_velocity(std::span<const double> Xi, std::span<double> U) {
  timed(timings_.interpolate, Phase::Interpolation, [&] { coupler_.interpolate_velocity(committed_.u, nodes(Xi), nodes(U)); });
}

void DistributedOperator::correct_positions(std::span<const Vec3> X) {
  if (X.size() != X_.size()) throw std::logic_error("DistributedOperator::correct_positions: one position per node");
  move_to(X);
  start_valid_ = false;  // S(X^n) f(X^n) at the corrected positions is computed when a trial needs it
}

bool DistributedOperator::trial_matches(std::span<const double> X) const {
  return trial_done_ && std::ranges::equal(trial_X_, X);
}

void DistributedOperator::commit(std::span<const double> X, double) {
  std::swap(committed_, trial_);
  // A trial driven by X^{n+1} itself (an implicit step's last) leaves S(X^{n+1}) f(X^{n+1}), the next step's start
  // force: a slab field, which does not depend on which process owns which membrane.
  // Agreed by all processes (a process's part may match where another's does not, or be empty).
  start_valid_ = !any_failed(fluid_.decomposition().communicator(), !trial_matches(X));
  if (start_valid_) std::swap(force_start_, force_);
  move_to(nodes(X));
}

void DistributedOperator::move_to(std::span<const Vec3> X) {
  ownership_.set_owned_positions(X);
  migrations_ += ownership_.migrate();
  refresh();
  U_.resize(X_.size());
  timed(timings_.interpolate, Phase::Interpolation, [&] { coupler_.interpolate_velocity(committed_.u, X_, U_); });
  trial_X_.clear();
  trial_done_ = false;
}

}  // namespace immerse
