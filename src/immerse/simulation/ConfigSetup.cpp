#include "immerse/simulation/ConfigSetup.hpp"

#include <algorithm>
#include <array>
#include <string>

#include "immerse/core/Error.hpp"
#include "immerse/fluid/PoiseuilleFlow.hpp"
#include "immerse/walls/WallGeometry.hpp"
#include "immerse/walls/WallSurface.hpp"

namespace immerse {

namespace {


/// The normal velocity of each wall on its faces (as NavierStokesSolver::apply_wall_values).
void set_wall_values(const Grid& grid, const FluidParams& params, FaceField& u) {
  for (int d = 0; d < 3; ++d) {
    if (grid.periodic(d)) continue;
    Array3& ud = u[d];
    const int e1 = (d + 1) % 3, e2 = (d + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      const double v = side == 0 ? params.wall_lower[d][d] : params.wall_upper[d][d];
      std::array<int, 3> q{};
      q[d] = side == 0 ? 0 : grid.n(d);
      for (q[e2] = 0; q[e2] < ud.n(e2); ++q[e2])
        for (q[e1] = 0; q[e1] < ud.n(e1); ++q[e1]) ud(q[0], q[1], q[2]) = v;
    }
  }
}

}  // namespace

Grid run_grid(const io::Config& c) {
  std::array<Boundary, 3> bc{};
  for (int d = 0; d < 3; ++d)
    bc[d] = c.get<std::string>(std::string("boundary.") + axis_name(d)) == "wall" ? Boundary::Wall : Boundary::Periodic;
  return Grid({c.get<int>("grid.nx"), c.get<int>("grid.ny"), c.get<int>("grid.nz")},
              {c.get<double>("domain.Lx"), c.get<double>("domain.Ly"), c.get<double>("domain.Lz")}, bc,
              c.get<Vec3>("domain.origin"));
}

FftPlanning run_fft_planning(const io::Config& c) {
  return c.get<std::string>("fluid.fft_planning") == "measure" ? FftPlanning::Measure : FftPlanning::Estimate;
}

FluidParams run_fluid_params(const io::Config& c) {
  FluidParams p;
  p.rho = c.get<double>("fluid.rho");
  p.mu = c.get<double>("fluid.mu");
  p.body_force = c.get<Vec3>("fluid.body_force");
  p.pressure = c.get<std::string>("fluid.pressure") == "extrapolated" ? PressurePredictor::Extrapolated
                                                                        : PressurePredictor::Lagged;
  for (std::size_t i = 0; i < c.count("membrane"); ++i) {
    const double ratio = c.entry("membrane", i).get<double>("viscosity_ratio");
    if (ratio != 1.0) p.variable_viscosity = true;
    p.implicit_ratio = std::max(p.implicit_ratio, ratio);
  }
  for (int d = 0; d < 3; ++d) {
    p.wall_lower[d] = c.get<Vec3>(std::string("boundary.") + axis_name(d) + "_lower_velocity");
    p.wall_upper[d] = c.get<Vec3>(std::string("boundary.") + axis_name(d) + "_upper_velocity");
  }
  // fluid.flow_rate: along one axis, through the box's cross-section normal to it.
  const Vec3 Q = c.get<Vec3>("fluid.flow_rate");
  int along = 0;
  for (int d = 0; d < 3; ++d)
    if (Q[d] != 0) p.flow_axis = d, ++along;
  if (along > 1)
    throw InputError("fluid.flow_rate = " + c.value_text("fluid.flow_rate") +
                     ": must be zero but along one axis, the axis of the flow");
  if (p.flow_axis >= 0) {
    double section = 1;
    for (int d = 0; d < 3; ++d)
      if (d != p.flow_axis) section *= c.get<double>(std::string("domain.L") + axis_name(d));
    p.flow_mean_velocity = Q[p.flow_axis] / section;
  }
  if (c.count("wall") > 0) {
    std::vector<WallShape> shapes;
    for (std::size_t i = 0; i < c.count("wall"); ++i) {
      const io::Config& w = c.entry("wall", i);
      WallShape s;
      const std::string shape = w.get<std::string>("shape");
      s.name = "wall[" + std::to_string(i) + "]";
      if (shape == "surface") {
        // The file's coordinates times scale are the box's; its closed surface bounds a solid or the fluid.
        const std::string file = w.get<std::string>("file");
        require(!file.empty(), s.name + ".file", "an STL or Gmsh file name when shape = \"surface\"");
        s.kind = WallShape::Kind::Surface;
        s.surface =
            std::make_shared<const WallSurface>(read_wall_surface(file, w.get<double>("scale"), s.name + ".file"));
        s.fluid_inside = w.get<std::string>("inside") == "fluid";
        shapes.push_back(s);
        continue;
      }
      s.kind = shape == "sphere"         ? WallShape::Kind::Sphere
               : shape == "box"          ? WallShape::Kind::Box
               : shape == "constriction" ? WallShape::Kind::Constriction
                                         : WallShape::Kind::Tube;
      s.radius = w.get<double>("radius");
      s.center = w.get<Vec3>("center");
      s.axis = w.get<Vec3>("axis");
      s.size = w.get<Vec3>("size");
      s.throat = w.get<Vec3>("throat");
      s.fluid_inside = shape == "box" && w.get<std::string>("inside") == "fluid";
      shapes.push_back(s);
    }
    p.walls = std::make_shared<const WallGeometry>(std::move(shapes), run_grid(c));
  }
  return p;
}

ContactSettings run_contact_settings(const io::Config& c, std::shared_ptr<const WallGeometry> walls) {
  ContactSettings s{c.get<double>("contact.range"), c.get<double>("contact.strength"), c.get<bool>("contact.walls"), {}};
  if (s.walls) s.shapes = std::move(walls);
  return s;
}

SolverSettings run_solver_settings(const io::Config& c) {
  SolverSettings s;
  s.theta = c.get<double>("time.theta");
  s.newton_rtol = c.get<double>("solver.newton_rtol");
  s.gmres_rtol = c.get<double>("solver.gmres_rtol");
  s.max_newton_its = c.get<int>("solver.max_newton_its");
  s.bfgs_memory = c.get<int>("solver.bfgs_memory");
  s.anderson_memory = c.get<int>("solver.anderson_memory");
  s.anderson_beta = c.get<double>("solver.anderson_beta");
  s.petsc_options = c.get<std::string>("solver.petsc_options");
  s.initial_guess = c.get<std::string>("solver.initial_guess") == "extrapolation"
                        ? SolverSettings::InitialGuess::Extrapolation
                        : SolverSettings::InitialGuess::Recurrence;
  return s;
}


FluidState run_initial_fluid_state(const io::Config& config, const Grid& grid, const FluidParams& params) {
  FluidState s;
  s.u = FaceField(grid);
  s.adv = FaceField(grid);
  s.p = Array3(grid.n(0), grid.n(1), grid.n(2));
  s.p_prev = Array3(grid.n(0), grid.n(1), grid.n(2));
  set_wall_values(grid, params, s.u);
  const std::string initial = config.get<std::string>("fluid.initial");
  if (initial == "poiseuille") {
    set_poiseuille_flow(grid, params, s.u);
    return s;
  }
  if (initial != "couette") return s;
  // The linear profile between the walls of the first wall axis: u = u_lower + (u_upper - u_lower) (x_a - o_a) / L_a.
  const auto& p = params;
  int a = -1;
  for (int d = 0; d < 3 && a < 0; ++d)
    if (!grid.periodic(d)) a = d;
  require(a >= 0, "fluid.initial", "\"rest\" when no axis has walls (\"couette\" needs walls)");
  for (int d = 0; d < 3; ++d) {
    auto& u = s.u[d];
    for (int k = 0; k < u.nz(); ++k)
      for (int j = 0; j < u.ny(); ++j)
        for (int i = 0; i < u.nx(); ++i) {
          const Vec3 x = grid.face_position(d, i, j, k);
          const double f = (x[a] - grid.origin()[a]) / grid.length(a);
          u(i, j, k) = p.wall_lower[a][d] + (p.wall_upper[a][d] - p.wall_lower[a][d]) * f;
        }
  }
  set_wall_values(grid, params, s.u);
  return s;
}

}  // namespace immerse
