#include "immerse/fluid/NavierStokesSolver.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>

#include "immerse/core/Error.hpp"
#include "immerse/fluid/MacStencil_K.hpp"
#include "immerse/fluid/NavierStokesStep_K.hpp"
#include "immerse/fluid/ViscousStress_K.hpp"

namespace immerse {

using namespace step_kernels;

namespace {

void ensure_shape(FaceField& f, const Grid& g) {
  for (int d = 0; d < 3; ++d)
    if (f[d].shape() != g.face_shape(d)) {
      f = FaceField(g);
      return;
    }
}

void ensure_shape(Array3& a, const Grid& g) {
  if (a.shape() != g.cell_shape()) a = Array3(g.n(0), g.n(1), g.n(2));
}

}  // namespace

double extrapolation_weight(double dt, double dt_prev, double dt_prev2) {
  return dt_prev2 > 0 ? (dt + dt_prev) / (dt_prev + dt_prev2) : 0.0;
}

NavierStokesSolver::NavierStokesSolver(const Grid& grid, const FluidParams& params, FftPlanning planning)
    : grid_(grid),
      params_(params),
      geom_(grid, params),
      geom0_(grid),
      mu_implicit_(params.variable_viscosity ? params.implicit_ratio * params.mu : params.mu),
      ustar_(grid),
      div_(grid.n(0), grid.n(1), grid.n(2)),
      phi_(grid.n(0), grid.n(1), grid.n(2)) {
  params_.validate(grid_);
  for (int l = 0; l < 4; ++l)
    solvers_[l] = std::make_unique<FftHelmholtzSolver>(grid_, static_cast<Layout>(l), planning, l < 3 ? &ustar_[l] : &phi_);
  if (params_.walls) walls_ = std::make_unique<GhostCellWalls>(grid_, *params_.walls);
  if (walls_ && params_.flow_axis >= 0 && !walls_->open_along(params_.flow_axis)) {
    const std::string a = axis_name(params_.flow_axis);
    throw InputError("fluid.flow_rate." + a + ": the [[wall]] shapes leave the fluid no path across the box along " +
                     a + " (drive a flow along an axis the walls let it through)");
  }
}

FluidState NavierStokesSolver::initial_state() const {
  FluidState s;
  s.u = FaceField(grid_);
  s.adv = FaceField(grid_);
  s.p = Array3(grid_.n(0), grid_.n(1), grid_.n(2));
  s.p_prev = Array3(grid_.n(0), grid_.n(1), grid_.n(2));
  apply_wall_values(s.u);
  return s;
}

void NavierStokesSolver::apply_wall_values(FaceField& u) const {
  for (int d = 0; d < 3; ++d) {
    if (grid_.periodic(d)) continue;
    Array3& ud = u[d];
    const int e1 = (d + 1) % 3, e2 = (d + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      const double v = side == 0 ? params_.wall_lower[d][d] : params_.wall_upper[d][d];
      mac::Index q{};
      q[d] = side == 0 ? 0 : grid_.n(d);
      for (q[e2] = 0; q[e2] < ud.n(e2); ++q[e2])
        for (q[e1] = 0; q[e1] < ud.n(e1); ++q[e1]) ud(q[0], q[1], q[2]) = v;
    }
  }
}

bool NavierStokesSolver::matches_grid(const FaceField& f) const {
  for (int d = 0; d < 3; ++d)
    if (f[d].shape() != grid_.face_shape(d)) return false;
  return true;
}

void NavierStokesSolver::check(const FluidState& in, double dt) const {
  if (!(std::isfinite(dt) && dt > 0)) require(false, "fluid.dt", dt, "> 0");  // (no strings built when valid)
  if (!matches_grid(in.u) || in.p.shape() != grid_.cell_shape() || (in.step > 0 && !matches_grid(in.adv)))
    throw std::invalid_argument("NavierStokesSolver: state does not match the grid");
}

void NavierStokesSolver::check_force(const FaceField& force) const {
  if (!matches_grid(force)) throw std::invalid_argument("NavierStokesSolver::step: force does not match the grid");
}

const Array3& NavierStokesSolver::momentum_pressure(const FluidState& in, double dt, Array3& scratch) const {
  if (params_.pressure == PressurePredictor::Lagged) return in.p;
  const double w = extrapolation_weight(dt, in.dt_prev, in.dt_prev2);
  if (w == 0.0) return in.p;
  if (in.p_prev.shape() != grid_.cell_shape())
    throw std::invalid_argument("NavierStokesSolver: state has no previous pressure to extrapolate from");
  ensure_shape(scratch, grid_);
  const long n = static_cast<long>(in.p.size());
  const double* const p = in.p.data();
  const double* const q = in.p_prev.data();
  double* const s = scratch.data();
#pragma omp parallel for schedule(static) if (n >= MacStencilGrid::kMinCellsForThreads)
  for (long i = 0; i < n; ++i) s[i] = p[i] + w * (p[i] - q[i]);
  return scratch;
}

template <class Rhs>
void NavierStokesSolver::advance(const FluidState& in, double dt, const Array3& p, FluidState& out, Rhs&& rhs) {
  ensure_shape(out.u, grid_);
  ensure_shape(out.adv, grid_);
  ensure_shape(out.p, grid_);
  ensure_shape(out.p_prev, grid_);

  const double rho = params_.rho, mu = mu_implicit_;
  const double c = mu * dt / (2.0 * rho);  // (I − c ∇_h²) u* = rhs

  for (int d = 0; d < 3; ++d) {
    rhs(d);
    if (walls_) {
      walls_->add_explicit_correction(d, in.u[d], 0.5 * params_.mu * dt / rho, ustar_[d]);
      walls_->solve(d, ustar_[d], 1.0, -c, *solvers_[d]);
    }
    else
      solvers_[d]->solve(ustar_[d], 1.0, -c);
  }
  project(dt, p, in.p, out);
  if (params_.flow_axis >= 0) hold_flow_rate(dt, out);
  if (params_.variable_viscosity) {
    ensure_shape(out.u_prev, grid_);
    for (int d = 0; d < 3; ++d) out.u_prev[d].values() = in.u[d].values();
  }

  out.dt_prev2 = in.dt_prev;
  out.dt_prev = dt;
  out.step = in.step + 1;
  out.time = in.time + dt;
}

void NavierStokesSolver::project(double dt, const Array3& p0, const Array3& pn, FluidState& out) {
  const MacStencilGrid& g = geom_;
  apply_wall_values(ustar_);
  // (11): ∇_h² φ = (ρ/Δt) D u*, Neumann walls.
  const double rho_dt = params_.rho / dt, dt_rho = dt / params_.rho;
  for_each_row(g, IndexBox{{0, 0, 0}, g.n}, [&](int j, int k, int i0, int i1) {
    if (mac::row_wraps(g, j, k))
      divergence_row<mac::WrappedRows>(g, ustar_, rho_dt, div_, phi_, j, k, i0, i1);
    else
      divergence_row<mac::Strided>(g, ustar_, rho_dt, div_, phi_, j, k, i0, i1);
  });
  solvers_[3]->solve(phi_, 0.0, 1.0);

  // (12) and (13).
  const double half_mu = 0.5 * mu_implicit_;
  for_each_row(g, IndexBox{{0, 0, 0}, g.n}, [&](int j, int k, int, int) {
    if (mac::row_wraps(g, j, k))
      project_and_update_row<mac::WrappedRows>(g, ustar_, phi_, div_, p0, pn, out, j, k, dt_rho, half_mu);
    else
      project_and_update_row<mac::Strided>(g, ustar_, phi_, div_, p0, pn, out, j, k, dt_rho, half_mu);
  });
  apply_wall_values(out.u);
}

// The step is linear in the body force (the advection term and the pressure are of the state before it): adding ΔG
// along the flow axis adds ΔG w, w = (I − c ∇_h²)⁻¹ Δt/ρ (divergence-free, as it does not vary along the axis).
void NavierStokesSolver::hold_flow_rate(double dt, FluidState& out) {
  const int a = params_.flow_axis;
  // The mean over the box, of the fluid's points only with walls (the flow through the walls' cross-sections).
  const auto mean = [&](const std::vector<double>& v) {
    double s = 0;
    for (std::size_t i = 0; i < v.size(); ++i)
      if (!walls_ || walls_->fluid(a, i)) s += v[i];
    return s / static_cast<double>(v.size());
  };
  // Walls that vary along a (a constriction): w has a divergence, and the response is w projected as u* is.
  const bool projected = walls_ && !params_.walls->invariant_along(a);
  if (flow_response_dt_ != dt) {
    ensure_shape(flow_response_.u, grid_);
    for (int d = 0; d < 3; ++d) {
      std::fill(ustar_[d].values().begin(), ustar_[d].values().end(), d == a ? dt / params_.rho : 0.0);
    }
    const double beta = -mu_implicit_ * dt / (2.0 * params_.rho);
    if (walls_)
      walls_->solve(a, ustar_[a], 1.0, beta, *solvers_[a]);
    else
      solvers_[a]->solve(ustar_[a], 1.0, beta);
    ensure_shape(flow_response_.p, grid_);
    ensure_shape(flow_response_.p_prev, grid_);
    if (projected) {
      Array3 zero(grid_.n(0), grid_.n(1), grid_.n(2));
      project(dt, zero, zero, flow_response_);
    } else {
      flow_response_.u[a] = ustar_[a];
      std::fill(flow_response_.p.values().begin(), flow_response_.p.values().end(), 0.0);
    }
    flow_response_mean_ = mean(flow_response_.u[a].values());
    flow_response_dt_ = dt;
  }
  const double G = (params_.flow_mean_velocity - mean(out.u[a].values())) / flow_response_mean_;
  for (int d = 0; d < 3; ++d) {
    if (!projected && d != a) continue;
    std::vector<double>& u = out.u[d].values();
    const std::vector<double>& w = flow_response_.u[d].values();
    for (std::size_t i = 0; i < u.size(); ++i) u[i] += G * w[i];
  }
  if (projected) {
    std::vector<double>& p = out.p.values();
    const std::vector<double>& q = flow_response_.p.values();
    for (std::size_t i = 0; i < p.size(); ++i) p[i] += G * q[i];
  }
  out.flow_force = G;
}

void NavierStokesSolver::step(const FluidState& in, const FaceField& force, double dt, FluidState& out,
                              const Array3* chi) {
  if (params_.variable_viscosity) {
    prepare(in, dt, own_);
    step(own_, force, out, chi);
    return;
  }
  check(in, dt);
  check_force(force);
  if (&in == &out) throw std::invalid_argument("NavierStokesSolver::step: `in` and `out` must be different states");
  out.adv_of = 0;
  const Array3& p = momentum_pressure(in, dt, ptilde_);
  // (9) in one pass: (u·∇_h u)^n into the new state, the right-hand side into u*.
  advance(in, dt, p, out, [&](int d) {
    build<true>(geom_, d, in, p, &force[d], rhs_coefficients(params_, in, dt, d), out.adv[d], ustar_[d]);
  });
}

void NavierStokesSolver::prepare(const FluidState& in, double dt, PreparedStep& prepared) const {
  check(in, dt);
  prepared.state_ = nullptr;  // (not prepared until the end)
  ensure_shape(prepared.adv_, grid_);
  ensure_shape(prepared.explicit_, grid_);
  const Array3& p = momentum_pressure(in, dt, prepared.pressure_);
  prepared.extrapolated_ = &p != &in.p;
  for (int d = 0; d < 3; ++d)
    build<false>(geom_, d, in, p, nullptr, rhs_coefficients(params_, in, dt, d), prepared.adv_[d],
                 prepared.explicit_[d]);
  if (params_.variable_viscosity) prepare_variable(in, dt, prepared);
  static std::atomic<std::uint64_t> prepares{0};  // (ids only: results never depend on it)
  prepared.state_ = &in;
  prepared.id_ = ++prepares;
  prepared.step_ = in.step;
  prepared.time_ = in.time;
  prepared.dt_ = dt;
}

void NavierStokesSolver::step(const PreparedStep& prepared, const FaceField& force, FluidState& out,
                              const Array3* chi) {
  const FluidState* const in = prepared.state_;
  if (!in) throw std::invalid_argument("NavierStokesSolver::step: the step was not prepared");
  if (!prepared.prepared_for(*in, prepared.dt_))
    throw std::logic_error("NavierStokesSolver::step: the state the step was prepared from has changed");
  if (in == &out)
    throw std::invalid_argument("NavierStokesSolver::step: `out` must not be the state the step was prepared from");
  check_force(force);
  const double dt = prepared.dt_;
  // (9) from the prepared explicit terms; their (u·∇_h u)^n into the new state unless it holds it already.
  const bool stress = params_.variable_viscosity && chi;
  if (stress && chi->shape() != grid_.cell_shape())
    throw std::invalid_argument("NavierStokesSolver::step: the viscosity field does not match the grid");
  const IndexBox box = stress ? variable_stress_box(*chi) : IndexBox{};
  const bool copy_adv = out.adv_of != prepared.id_ || !matches_grid(out.adv);
  out.adv_of = 0;
  const auto rhs = [&]<bool CopyAdv>(int d) {
    const RhsCoefficients c = rhs_coefficients(params_, *in, dt, d);
    for_each_row(geom_, face_box(geom_, d), [&](int j, int k, int i0, int i1) {
      rhs_row<CopyAdv>(in->u[d], prepared.explicit_[d], force[d], prepared.adv_[d], c, ustar_[d], out.adv[d], j, k, i0,
                       i1);
    });
  };
  advance(*in, dt, prepared.extrapolated_ ? prepared.pressure_ : in->p, out, [&](int d) {
    if (copy_adv)
      rhs.template operator()<true>(d);
    else
      rhs.template operator()<false>(d);
    if (stress) add_variable_stress(prepared.utilde_, *chi, dt, d, box);
  });
  out.adv_of = prepared.id_;
}

void NavierStokesSolver::prepare_variable(const FluidState& in, double dt, PreparedStep& prepared) const {
  ensure_shape(prepared.utilde_, grid_);
  const bool extrapolate = !first_step(in) && matches_grid(in.u_prev);
  const double half_r = extrapolate ? 0.5 * dt / in.dt_prev : 0.0;
  const double dmu = mu_implicit_ - params_.mu;
  for (int d = 0; d < 3; ++d) {
    const long n = static_cast<long>(in.u[d].size());
    const double* const u = in.u[d].data();
    const double* const up = extrapolate ? in.u_prev[d].data() : u;
    double* const ut = prepared.utilde_[d].data();
    if (dmu != 0) {
      // (μ_p − μ) ∇_h²(u^n/2 − ũ) with homogeneous walls, from u^n/2 − ũ held in utilde_ meanwhile.
#pragma omp parallel for schedule(static) if (geom_.threaded())
      for (long i = 0; i < n; ++i) ut[i] = 0.5 * u[i] - (u[i] + half_r * (u[i] - up[i]));
      Array3& e = prepared.explicit_[d];
      const Array3& w = prepared.utilde_[d];
      for_each_face(geom_, d, [&](int i, int j, int k) {
        e(i, j, k) += dmu * mac::laplacian_face(w, geom0_, d, mac::Index{i, j, k});
      });
    }
#pragma omp parallel for schedule(static) if (geom_.threaded())
    for (long i = 0; i < n; ++i) ut[i] = u[i] + half_r * (u[i] - up[i]);
  }
}

IndexBox NavierStokesSolver::variable_stress_box(const Array3& chi) const {
  const MacStencilGrid& g = geom_;
  std::array<int, 3> lo = g.n, hi{-1, -1, -1};
  for (int k = 0; k < g.n[2]; ++k)
    for (int j = 0; j < g.n[1]; ++j) {
      const double* const row = chi.data() + chi.index(0, j, k);
      for (int i = 0; i < g.n[0]; ++i)
        if (row[i] != 0.0) {
          const std::array<int, 3> q{i, j, k};
          for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], q[a]);
            hi[a] = std::max(hi[a], q[a]);
          }
        }
    }
  if (hi[0] < 0) return IndexBox{{0, 0, 0}, {0, 0, 0}};
  IndexBox box{};
  for (int a = 0; a < 3; ++a) {
    if (g.periodic[a] && (lo[a] < 1 || hi[a] > g.n[a] - 2)) {
      box.begin[a] = 0;
      box.end[a] = g.n[a];
    } else {
      box.begin[a] = std::max(lo[a] - 1, 0);
      box.end[a] = std::min(hi[a] + 2, g.n[a]);
    }
  }
  return box;
}

void NavierStokesSolver::add_variable_stress(const FaceField& utilde, const Array3& chi, double dt, int d,
                                             const IndexBox& box) {
  const MacStencilGrid& g = geom_;
  const double c = dt / params_.rho * params_.mu;
  Array3& rhs = ustar_[d];
  const int i0 = std::max(box.begin[0], g.first(d, 0)), j0 = std::max(box.begin[1], g.first(d, 1)),
            k0 = std::max(box.begin[2], g.first(d, 2));
#pragma omp parallel for collapse(2) schedule(static) if (g.threaded())
  for (int k = k0; k < box.end[2]; ++k)
    for (int j = j0; j < box.end[1]; ++j)
      for (int i = i0; i < box.end[0]; ++i)
        rhs(i, j, k) += c * mac::stress_divergence(utilde, chi, g, d, mac::Index{i, j, k});
}

}  // namespace immerse
