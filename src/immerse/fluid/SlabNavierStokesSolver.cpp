#include "immerse/fluid/SlabNavierStokesSolver.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>

#include "immerse/core/Error.hpp"
#include "immerse/fluid/MacStencil_K.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/fluid/ViscousStress_K.hpp"

namespace immerse {

using namespace step_kernels;

namespace {

/// (12) over the rows of `box` of component D: u^{n+1} = u* − (Δt/ρ) G φ.
template <int D>
void project(const MacStencilGrid& g, const IndexBox& box, const Array3& us, const Array3& phi, Array3& un1,
             double dt_rho) {
  for_each_row(g, box, [&](int j, int k, int i0, int i1) {
    if (mac::row_wraps(g, j, k))
      project_row<D, mac::WrappedRows>(g, us, phi, un1, j, k, i0, i1, dt_rho);
    else
      project_row<D, mac::Strided>(g, us, phi, un1, j, k, i0, i1, dt_rho);
  });
}

}  // namespace

SlabNavierStokesSolver::SlabNavierStokesSolver(const Grid& grid, const FluidParams& params, Communicator comm,
                                               FftPlanning planning)
    : grid_(grid),
      params_(params),
      slabs_(grid, comm),
      halo_(slabs_, params.wall_lower[2], params.wall_upper[2]),
      geom_(grid, params),
      local_(geom_),
      local0_(grid),
      halo0_(slabs_, Vec3{}, Vec3{}),
      mu_implicit_(params.variable_viscosity ? params.implicit_ratio * params.mu : params.mu) {
  params_.validate(grid_);
  require(!params_.walls, "[[wall]]", "absent in a run on several processes (walls of any shape run on one process)");
  for (MacStencilGrid* g : {&local_, &local0_}) {
    g->n[2] = slabs_.local_shape(Layout::Pressure)[2];
    g->periodic[2] = true;
  }
  const int off = slabs_.offset();
  for (int d = 0; d < 3; ++d) {
    const PlaneRange own = slabs_.owned(velocity_layout(d));
    IndexBox all = face_box(geom_, d), fast = interior_face_box(geom_, d);
    all.begin[2] = own.begin - off;
    all.end[2] = own.end - off;
    // The row kernels on the owned planes away from the walls along z; the generic ones (with wall sources) there.
    const int fb = std::max(fast.begin[2], own.begin), fe = std::max(std::min(fast.end[2], own.end), fb);
    fast.begin[2] = fb - off;
    fast.end[2] = fe - off;
    region_[d] = BuildRegion{all, fast, &geom_, off};
  }
  for (int l = 0; l < 4; ++l) {
    const Layout layout = static_cast<Layout>(l);
    solvers_[l] = std::make_unique<SlabFftHelmholtzSolver>(grid_, layout, comm, slabs_.block(), planning);
    const PlaneRange own = slabs_.owned(layout);
    if (solvers_[l]->first_array_plane() != own.begin || solvers_[l]->local_planes() != own.count())
      throw std::logic_error("SlabNavierStokesSolver: a fast solver's planes are not the decomposition's");
  }
  for (int d = 0; d < 3; ++d) ustar_[d] = slabs_.make(velocity_layout(d));
  div_ = slabs_.make(Layout::Pressure);
  phi_ = slabs_.make(Layout::Pressure);
  if (params_.variable_viscosity)
    for (int d = 0; d < 3; ++d) {
      explicit_[d] = slabs_.make(velocity_layout(d));
      utilde_[d] = slabs_.make(velocity_layout(d));
    }
}

bool SlabNavierStokesSolver::is_slab(const FaceField& f) const {
  for (int d = 0; d < 3; ++d)
    if (f[d].shape() != slabs_.local_shape(velocity_layout(d))) return false;
  return true;
}

void SlabNavierStokesSolver::check(const FluidState& in, double dt, const FaceField& force) const {
  if (!(std::isfinite(dt) && dt > 0)) require(false, "fluid.dt", dt, "> 0");
  const std::array<int, 3> cells = slabs_.local_shape(Layout::Pressure);
  if (!is_slab(in.u) || in.p.shape() != cells || in.p_prev.shape() != cells || (in.step > 0 && !is_slab(in.adv)))
    throw std::invalid_argument("SlabNavierStokesSolver: state is not a slab state of this decomposition");
  if (!is_slab(force))
    throw std::invalid_argument("SlabNavierStokesSolver::step: force is not a slab field of this decomposition");
}

void SlabNavierStokesSolver::ensure_slabs(FluidState& s) const {
  for (FaceField* f : {&s.u, &s.adv})
    if (!is_slab(*f))
      for (int d = 0; d < 3; ++d) (*f)[d] = slabs_.make(velocity_layout(d));
  for (Array3* a : {&s.p, &s.p_prev})
    if (a->shape() != slabs_.local_shape(Layout::Pressure)) *a = slabs_.make(Layout::Pressure);
}

void SlabNavierStokesSolver::apply_wall_values(FaceField& u) const {
  for (int d = 0; d < 2; ++d) {
    if (grid_.periodic(d)) continue;
    Array3& ud = u[d];
    for (int k = 0; k < ud.nz(); ++k)
      for (int j = 0; j < ud.ny(); ++j)
        for (int i = 0; i < ud.nx(); ++i) {
          const int q = d == 0 ? i : j;
          if (q == 0) ud(i, j, k) = params_.wall_lower[d][d];
          if (q == grid_.n(d)) ud(i, j, k) = params_.wall_upper[d][d];
        }
  }
}

void SlabNavierStokesSolver::step(const FluidState& in, const FaceField& force, double dt, FluidState& out,
                                  const Array3* chi) {
  check(in, dt, force);
  if (&in == &out) throw std::invalid_argument("SlabNavierStokesSolver::step: `in` and `out` must be different states");
  const bool variable = params_.variable_viscosity;
  if (variable && chi && chi->shape() != slabs_.local_shape(Layout::Pressure))
    throw std::invalid_argument("SlabNavierStokesSolver::step: the viscosity field is not a slab array of the cells");
  ensure_slabs(out);
  out.adv_of = 0;
  const int off = slabs_.offset();

  // The pressure of (9): p^{n−1/2} or p̃, over the whole slab (the ghosts of p and p_prev are valid).
  const Array3* p = &in.p;
  if (params_.pressure == PressurePredictor::Extrapolated) {
    const double w = extrapolation_weight(dt, in.dt_prev, in.dt_prev2);
    if (w != 0.0) {
      if (ptilde_.shape() != in.p.shape()) ptilde_ = slabs_.make(Layout::Pressure);
      for (std::size_t q = 0; q < in.p.size(); ++q) ptilde_[q] = in.p[q] + w * (in.p[q] - in.p_prev[q]);
      p = &ptilde_;
    }
  }

  // (9): the right-hand side on the owned faces and (u·∇_h u)^n into the new state, then the three solves.
  // With a variable viscosity as NavierStokesSolver's prepared step: the explicit terms first, then the right-hand
  // side under the force and the stress term.
  const double rho = params_.rho, mu = mu_implicit_;
  const double c = mu * dt / (2.0 * rho);
  const double dt_rho = dt / rho;
  if (variable) {
    for (int d = 0; d < 3; ++d)
      build<false>(local_, region_[d], d, in, *p, nullptr, rhs_coefficients(params_, in, dt, d), out.adv[d],
                   explicit_[d]);
    prepare_variable(in, dt);
  }
  for (int d = 0; d < 3; ++d) {
    const RhsCoefficients coefficients = rhs_coefficients(params_, in, dt, d);
    if (variable) {
      for_each_row(local_, region_[d].all, [&](int j, int k, int i0, int i1) {
        rhs_row<false>(in.u[d], explicit_[d], force[d], out.adv[d], coefficients, ustar_[d], out.adv[d], j, k, i0, i1);
      });
      if (chi) add_variable_stress(*chi, dt, d);
    } else {
      build<true>(local_, region_[d], d, in, *p, &force[d], coefficients, out.adv[d], ustar_[d]);
    }
    solvers_[d]->solve(ustar_[d], slabs_.owned(velocity_layout(d)).begin - off, 1.0, -c);
  }
  apply_wall_values(ustar_);
  halo_.exchange(ustar_[2], Layout::VelocityZ);  // D u* reads u*_z on both sides of the owned cells

  // (11): ∇_h² φ = (ρ/Δt) D u* on the owned cells.
  const double rho_dt = rho / dt;
  const PlaneRange cells = slabs_.cells();
  const IndexBox cell_box{{0, 0, cells.begin - off}, {grid_.n(0), grid_.n(1), cells.end - off}};
  for_each_row(local_, cell_box, [&](int j, int k, int i0, int i1) {
    if (mac::row_wraps(local_, j, k))
      divergence_row<mac::WrappedRows>(local_, ustar_, rho_dt, div_, phi_, j, k, i0, i1);
    else
      divergence_row<mac::Strided>(local_, ustar_, rho_dt, div_, phi_, j, k, i0, i1);
  });
  solvers_[3]->solve(phi_, cells.begin - off, 0.0, 1.0);
  halo_.exchange(phi_, Layout::Pressure);  // G φ reads φ below (and, for u_z between walls, above) the owned faces

  // (12) and (13).
  project<0>(local_, region_[0].all, ustar_[0], phi_, out.u[0], dt_rho);
  project<1>(local_, region_[1].all, ustar_[1], phi_, out.u[1], dt_rho);
  project<2>(local_, region_[2].all, ustar_[2], phi_, out.u[2], dt_rho);
  const double half_mu = 0.5 * mu;
  for (int k = cell_box.begin[2]; k < cell_box.end[2]; ++k) {
    const std::size_t o = phi_.index(0, 0, k);
    const std::size_t n = static_cast<std::size_t>(grid_.n(0)) * grid_.n(1);
    for (std::size_t q = o; q < o + n; ++q) out.p[q] = (*p)[q] + phi_[q] - half_mu * div_[q];
  }
  out.p_prev.values() = in.p.values();  // with its ghosts
  if (variable)
    for (int d = 0; d < 3; ++d) out.u_prev[d] = in.u[d];  // with its ghosts
  apply_wall_values(out.u);
  if (params_.flow_axis >= 0) hold_flow_rate(dt, out);
  for (int d = 0; d < 3; ++d) halo_.exchange(out.u[d], velocity_layout(d));
  halo_.exchange(out.p, Layout::Pressure);

  out.dt_prev2 = in.dt_prev;
  out.dt_prev = dt;
  out.step = in.step + 1;
  out.time = in.time + dt;
}

// As NavierStokesSolver::hold_flow_rate, the means summed over the planes each process holds.
void SlabNavierStokesSolver::hold_flow_rate(double dt, FluidState& out) {
  const int a = params_.flow_axis;
  const Layout layout = velocity_layout(a);
  const PlaneRange held = slabs_.held(layout);
  const auto mean = [&](const Array3& v) {
    const std::size_t plane = static_cast<std::size_t>(v.nx()) * v.ny();
    const double* p = v.data() + v.index(0, 0, held.begin - slabs_.offset());
    double s = 0;
    for (std::size_t q = 0; q < plane * held.count(); ++q) s += p[q];
    const auto shape = grid_.face_shape(a);
    return slabs_.communicator().sum(s) / (double(shape[0]) * shape[1] * shape[2]);
  };
  if (flow_response_dt_ != dt) {
    Array3& w = ustar_[a];  // free again after the projection
    std::fill(w.values().begin(), w.values().end(), dt / params_.rho);
    solvers_[a]->solve(w, slabs_.owned(layout).begin - slabs_.offset(), 1.0, -mu_implicit_ * dt / (2.0 * params_.rho));
    flow_response_ = w;
    flow_response_mean_ = mean(w);
    flow_response_dt_ = dt;
  }
  const double G = (params_.flow_mean_velocity - mean(out.u[a])) / flow_response_mean_;
  std::vector<double>& u = out.u[a].values();
  const std::vector<double>& w = flow_response_.values();
  for (std::size_t i = 0; i < u.size(); ++i) u[i] += G * w[i];
  out.flow_force = G;
}

void SlabNavierStokesSolver::prepare_variable(const FluidState& in, double dt) {
  const bool extrapolate = !first_step(in) && is_slab(in.u_prev);
  const double half_r = extrapolate ? 0.5 * dt / in.dt_prev : 0.0;
  const double dmu = mu_implicit_ - params_.mu;
  for (int d = 0; d < 3; ++d) {
    const Layout layout = velocity_layout(d);
    const std::size_t n = in.u[d].size();
    const double* const u = in.u[d].data();
    const double* const up = extrapolate ? in.u_prev[d].data() : u;
    double* const ut = utilde_[d].data();
    if (dmu != 0) {
      // (μ_p − μ) ∇_h²(u^n/2 − ũ) with homogeneous walls, from u^n/2 − ũ held in utilde_ meanwhile.
      for (std::size_t q = 0; q < n; ++q) ut[q] = 0.5 * u[q] - (u[q] + half_r * (u[q] - up[q]));
      halo0_.exchange(utilde_[d], layout);
      const IndexBox& box = region_[d].all;
      Array3& e = explicit_[d];
      for (int k = box.begin[2]; k < box.end[2]; ++k)
        for (int j = box.begin[1]; j < box.end[1]; ++j)
          for (int i = box.begin[0]; i < box.end[0]; ++i)
            e(i, j, k) += dmu * mac::laplacian_face(utilde_[d], local0_, d, mac::Index{i, j, k});
    }
    for (std::size_t q = 0; q < n; ++q) ut[q] = u[q] + half_r * (u[q] - up[q]);
    halo_.exchange(utilde_[d], layout);  // beyond a z wall the ghost 2 u_w − ũ_0 (or the wall face) of the kernel
  }
}

void SlabNavierStokesSolver::add_variable_stress(const Array3& chi, double dt, int d) {
  // The faces whose stencil reads a non-zero χ (cells within one index along each axis), as
  // NavierStokesSolver::variable_stress_box on the slab's planes (ghosts included); zero χ adds nothing elsewhere.
  std::array<int, 3> lo{chi.nx(), chi.ny(), chi.nz()}, hi{-1, -1, -1};
  for (int k = 0; k < chi.nz(); ++k)
    for (int j = 0; j < chi.ny(); ++j)
      for (int i = 0; i < chi.nx(); ++i)
        if (chi(i, j, k) != 0.0) {
          const std::array<int, 3> q{i, j, k};
          for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], q[a]);
            hi[a] = std::max(hi[a], q[a]);
          }
        }
  if (hi[0] < 0) return;
  const IndexBox& own = region_[d].all;
  IndexBox box{};
  for (int a = 0; a < 3; ++a) {
    if (a < 2 && local_.periodic[a] && (lo[a] < 1 || hi[a] > local_.n[a] - 2)) {
      box.begin[a] = own.begin[a];
      box.end[a] = own.end[a];
    } else {
      box.begin[a] = std::max(lo[a] - 1, own.begin[a]);
      box.end[a] = std::min(hi[a] + 2, own.end[a]);
    }
  }
  const double c = dt / params_.rho * params_.mu;
  Array3& rhs = ustar_[d];
  for (int k = box.begin[2]; k < box.end[2]; ++k)
    for (int j = box.begin[1]; j < box.end[1]; ++j)
      for (int i = box.begin[0]; i < box.end[0]; ++i)
        rhs(i, j, k) += c * mac::stress_divergence(utilde_, chi, local_, d, mac::Index{i, j, k});
}

void SlabNavierStokesSolver::exchange_ghosts(FluidState& s) const {
  for (int d = 0; d < 3; ++d) halo_.exchange(s.u[d], velocity_layout(d));
  if (is_slab(s.u_prev))
    for (int d = 0; d < 3; ++d) halo_.exchange(s.u_prev[d], velocity_layout(d));
  halo_.exchange(s.p, Layout::Pressure);
  halo_.exchange(s.p_prev, Layout::Pressure);
}

FluidState SlabNavierStokesSolver::scatter(const FluidState& global) const {
  FluidState s;
  ensure_slabs(s);
  for (int d = 0; d < 3; ++d) {
    slabs_.scatter(global.u[d], velocity_layout(d), s.u[d]);
    if (global.adv[d].shape() == grid_.face_shape(d)) slabs_.scatter(global.adv[d], velocity_layout(d), s.adv[d]);
    if (params_.variable_viscosity && global.u_prev[d].shape() == grid_.face_shape(d)) {
      s.u_prev[d] = slabs_.make(velocity_layout(d));
      slabs_.scatter(global.u_prev[d], velocity_layout(d), s.u_prev[d]);
    }
  }
  slabs_.scatter(global.p, Layout::Pressure, s.p);
  if (global.p_prev.shape() == grid_.cell_shape()) slabs_.scatter(global.p_prev, Layout::Pressure, s.p_prev);
  s.dt_prev = global.dt_prev;
  s.dt_prev2 = global.dt_prev2;
  s.step = global.step;
  s.time = global.time;
  s.flow_force = global.flow_force;
  exchange_ghosts(s);
  return s;
}

FaceField SlabNavierStokesSolver::scatter(const FaceField& global) const {
  FaceField f;
  for (int d = 0; d < 3; ++d) slabs_.scatter(global[d], velocity_layout(d), f[d]);
  return f;
}

FluidState SlabNavierStokesSolver::gather(const FluidState& local) const {
  FluidState s;
  s.u = gather(local.u);
  s.adv = gather(local.adv);
  if (is_slab(local.u_prev)) s.u_prev = gather(local.u_prev);
  s.p = slabs_.gather(local.p, Layout::Pressure);
  s.p_prev = slabs_.gather(local.p_prev, Layout::Pressure);
  s.dt_prev = local.dt_prev;
  s.dt_prev2 = local.dt_prev2;
  s.step = local.step;
  s.time = local.time;
  s.flow_force = local.flow_force;
  return s;
}

FaceField SlabNavierStokesSolver::gather(const FaceField& local) const {
  FaceField f;
  for (int d = 0; d < 3; ++d) f[d] = slabs_.gather(local[d], velocity_layout(d));
  return f;
}

}  // namespace immerse
