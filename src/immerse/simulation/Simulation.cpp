#include "immerse/simulation/Simulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "immerse/core/Error.hpp"
#include "immerse/fluid/PoiseuilleFlow.hpp"
#include "immerse/coupling/NodeDiagnostics.hpp"
#include "immerse/io/TomlFormat.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/membrane/GmshReader.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/membrane/MeshValidation.hpp"
#include "immerse/membrane/NeoHookean.hpp"
#include "immerse/membrane/Shape.hpp"
#include "immerse/membrane/Skalak.hpp"
#include "immerse/membrane/VolumeCorrection.hpp"
#include "immerse/membrane/Yeoh.hpp"
#include "immerse/simulation/CellPacking.hpp"
#include "immerse/simulation/MembraneClearance.hpp"
#include "immerse/simulation/RunSchema.hpp"
#include "immerse/timestep/DenseBfgs.hpp"

namespace immerse {

namespace {

const char* kAxes[3] = {"x", "y", "z"};

Grid make_grid(const io::Config& c) {
  std::array<Boundary, 3> bc{};
  for (int d = 0; d < 3; ++d)
    bc[d] = c.get<std::string>(std::string("boundary.") + kAxes[d]) == "wall" ? Boundary::Wall : Boundary::Periodic;
  return Grid({c.get<int>("grid.nx"), c.get<int>("grid.ny"), c.get<int>("grid.nz")},
              {c.get<double>("domain.Lx"), c.get<double>("domain.Ly"), c.get<double>("domain.Lz")}, bc,
              c.get<Vec3>("domain.origin"));
}

FluidParams make_fluid(const io::Config& c) {
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
    p.wall_lower[d] = c.get<Vec3>(std::string("boundary.") + kAxes[d] + "_lower_velocity");
    p.wall_upper[d] = c.get<Vec3>(std::string("boundary.") + kAxes[d] + "_upper_velocity");
  }
  return p;
}

ContactSettings make_contact(const io::Config& c) {
  return {c.get<double>("contact.range"), c.get<double>("contact.strength"), c.get<bool>("contact.walls")};
}

SolverSettings make_settings(const io::Config& c) {
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

Shape shape_of(const io::Config& m, bool reference) {
  Shape s;
  if (reference && m.get<std::string>("reference") == "sphere") {
    s.form = Sphere{m.get<double>("reference_radius")};
  } else {
    const std::string kind = m.get<std::string>("shape");
    if (kind == "sphere") s.form = Sphere{m.get<double>("radius")};
    else if (kind == "ellipsoid") {
      const Vec3 ax = m.get<Vec3>("semi_axes");
      s.form = Ellipsoid{ax.x, ax.y, ax.z};
    } else if (kind == "oblate") {
      s.form = OblateSpheroid{m.get<double>("radius"), m.get<double>("aspect_ratio"), m.get<double>("inclination")};
    } else {
      BiconcaveCell rbc;
      rbc.R0 = m.get<double>("R0");
      s.form = rbc;
    }
  }
  const Vec3 axis = m.get<Vec3>("rotation_axis");
  const double angle = m.get<double>("rotation_angle");
  if (angle != 0.0) {
    require(norm(axis) > 0, "rotation_axis", "a non-zero vector");
    s.placement.rotation = rotation_about(axis, angle);
  }
  s.placement.translation = m.get<Vec3>("center");
  return s;
}

MaterialLaw law_of(const io::Config& m) {
  const std::string law = m.get<std::string>("law");
  if (law == "neo_hookean") return NeoHookean(m.get<double>("Es"));
  if (law == "yeoh") return Yeoh(m.get<double>("C10"), m.get<double>("C30"));
  return Skalak(m.get<double>("C11"), m.get<double>("C21"));
}

std::string membrane_name(std::size_t m) { return "membrane[" + std::to_string(m) + "]"; }

// mesh.reference_file must be mesh.file in another shape: the same nodes joined into the same elements.
void check_same_elements(const Mesh& reference, const Mesh& mesh) {
  const std::string same = ": must be the mesh of mesh.file in another shape (the same nodes and elements)";
  const auto count = [](std::size_t n, const char* what) { return std::to_string(n) + " " + what; };
  if (reference.num_nodes() != mesh.num_nodes())
    throw InputError("mesh.reference_file: has " + count(reference.num_nodes(), "nodes") + ", mesh.file " +
                     count(mesh.num_nodes(), "nodes") + same);
  if (reference.num_elements() != mesh.num_elements())
    throw InputError("mesh.reference_file: has " + count(reference.num_elements(), "elements") + ", mesh.file " +
                     count(mesh.num_elements(), "elements") + same);
  for (std::size_t e = 0; e < mesh.num_elements(); ++e)
    if (reference.elements[e] != mesh.elements[e]) {
      const auto nodes = [](const std::array<int, 6>& el) {
        std::string s;
        for (int n : el) s += (s.empty() ? "" : " ") + std::to_string(n);
        return s;
      };
      throw InputError("mesh.reference_file: element " + std::to_string(e) + " joins nodes " +
                       nodes(reference.elements[e]) + ", in mesh.file " + nodes(mesh.elements[e]) + same);
    }
}

// For a mesh read from a file, the likely reason it does not fit the box: another length unit.
std::string unit_hint(const io::Config& config, std::size_t m) {
  return config.get<std::string>(membrane_name(m) + ".mesh.family") == "file"
             ? " (is the mesh file in another unit? mesh.scale converts it to metres, e.g. 1e-6 for micrometres)"
             : "";
}

}  // namespace

Simulation::Simulation(const io::Config& config, const std::function<bool()>& stop_requested)
    : config_(config),
      end_time_(config.get<double>("time.end")),
      max_speed_(config.get<double>("time.max_speed")),
      grid_(make_grid(config)),
      threads_(ThreadGovernor::from_environment()),
      fluid_(grid_, make_fluid(config),
             config.get<std::string>("fluid.fft_planning") == "measure" ? FftPlanning::Measure : FftPlanning::Estimate),
      coupler_(grid_, delta_kernel(config.get<std::string>("coupling.kernel"))),
      stepper_(config.get<double>("time.dt"), config.get<double>("time.dt_min")) {
  build_membranes();
  pack_membranes(stop_requested);
  check_geometry();
  std::vector<const ElasticMembrane*> ms;
  for (auto& m : membranes_) ms.push_back(m.get());
  op_ = std::make_unique<ImmersedBoundaryOperator>(fluid_, coupler_, ms, initial_, initial_fluid_state(),
                                                   make_contact(config), viscosity_ratio_);
  op_->set_thread_governor(threads_);
  integrator_ = make_integrator(config.get<std::string>("time.scheme"), make_settings(config));
  if (integrator_->name() == "bfgs" && op_->size() > DenseBfgs::max_unknowns)
    throw InputError("time.scheme = \"bfgs\": the dense quasi-Newton matrix of eq. (35) is limited to " +
                     std::to_string(DenseBfgs::max_unknowns) + " unknowns and this run has " +
                     std::to_string(op_->size()) + " (use \"jfnk\", \"anderson\" or \"lbfgs\")");
  integrator_->prepare(op_->size());
}

void Simulation::build_membranes() {
  for (std::size_t i = 0; i < config_.count("membrane"); ++i) {
    const io::Config& m = config_.entry("membrane", i);
    const std::string name = membrane_name(i);
    try {
      const std::string family = m.get<std::string>("mesh.family");
      const int level = m.get<int>("mesh.level");
      Mesh mesh;
      std::vector<Vec3> initial, reference;
      if (family == "file") {
        // A user's mesh is the initial shape itself, its length unit times mesh.scale, placed by center and rotation;
        // its reference is the same shape, the reference sphere over the directions of its nodes (for star-shaped
        // meshes), or the shape of mesh.reference_file, scaled and placed alike.
        const std::string file = m.get<std::string>("mesh.file");
        require(!file.empty(), "mesh.file", "a Gmsh file name when mesh.family = \"file\"");
        const double scale = m.get<double>("mesh.scale");
        const RigidTransform place = shape_of(m, false).placement;
        const auto placed = [&](const Mesh& read) {
          std::vector<Vec3> X;
          for (const auto& p : read.nodes) X.push_back(place.rotation * (scale * p) + place.translation);
          return X;
        };
        mesh = read_gmsh(file);
        initial = placed(mesh);
        const std::string kind = m.get<std::string>("reference");
        if (kind == "sphere") {
          if (!encloses(mesh, mesh.nodes, Vec3{0, 0, 0}))
            throw InputError("reference = \"sphere\": the origin of mesh.file must lie inside the mesh (the reference "
                             "sphere maps each node's direction from it: the mesh must be star-shaped about its origin)");
          std::vector<Vec3> unit;
          for (const auto& p : mesh.nodes) unit.push_back(normalized(p));
          reference = map_sphere(shape_of(m, true), unit);
        } else if (kind == "file") {
          const std::string reference_file = m.get<std::string>("mesh.reference_file");
          require(!reference_file.empty(), "mesh.reference_file", "a Gmsh file name when reference = \"file\"");
          const Mesh stress_free = read_gmsh(reference_file);
          check_same_elements(stress_free, mesh);
          reference = placed(stress_free);
        } else {
          reference = initial;
        }
      } else {
        mesh = family == "icosahedral" ? icosahedral_sphere(level) : octahedral_sphere(level);
        initial = map_sphere(shape_of(m, false), mesh.nodes);
        reference = map_sphere(shape_of(m, true), mesh.nodes);
      }
      mesh.nodes = initial;
      validate_closed_mesh(mesh, name);
      add_membrane(m, std::move(mesh), std::move(initial), std::move(reference));
    } catch (const InputError& e) {
      // A key of the entry becomes membrane[i].key; the membrane's own "membrane reference element 3" becomes
      // "membrane[i] reference element 3".
      const std::string what = e.what();
      throw InputError(what.rfind("membrane ", 0) == 0 ? name + what.substr(8) : name + "." + what);
    }
  }
}

void Simulation::add_membrane(const io::Config& m, Mesh mesh, std::vector<Vec3> initial, std::vector<Vec3> reference) {
  Bending bending{m.get<double>("kappa_B"), m.get<std::string>("bending_reference") == "rest"
                                                 ? ReferenceCurvature::RestShape
                                                 : ReferenceCurvature::Zero};
  membranes_.push_back(std::make_unique<ElasticMembrane>(
      mesh, reference, law_of(m), bending,
      m.get<std::string>("force") == "energy" ? ForceMethod::Energy : ForceMethod::Contour,
      ConstraintModuli{m.get<double>("volume_modulus"), m.get<double>("area_modulus")}));
  corrected_volume_.push_back(m.get<std::string>("volume_correction") == "normal_shift"
                                  ? std::optional<double>(volume(mesh, initial))
                                  : std::nullopt);
  viscosity_ratio_.push_back(m.get<double>("viscosity_ratio"));
  meshes_.push_back(std::move(mesh));
  references_.push_back(std::move(reference));
  initial_.push_back(std::move(initial));
}

// [packing]: membrane[0] is the template; its copies replace it, placed by CellPacking.
void Simulation::pack_membranes(const std::function<bool()>& stop_requested) {
  const double fraction = config_.get<double>("packing.volume_fraction");
  const auto count = config_.get<std::int64_t>("packing.count");
  if (fraction == 0 && count == 0) return;
  if (fraction > 0 && count > 0)
    throw InputError("packing.count = " + std::to_string(count) + " and packing.volume_fraction = " +
                     config_.value_text("packing.volume_fraction") + ": give only one of them");
  const char* key = count > 0 ? "packing.count" : "packing.volume_fraction";
  if (config_.count("membrane") != 1)
    throw InputError(std::string(key) + ": packs copies of one [[membrane]] entry, the template; " +
                     std::to_string(config_.count("membrane")) + " are given");
  // The template's placement must be the default one (as config.resolved.toml records it): the packer's replaces it.
  const io::Config& t = config_.entry("membrane", 0);
  Vec3 box_centre;
  for (int a = 0; a < 3; ++a) box_centre[a] = grid_.origin()[a] + 0.5 * grid_.length(a);
  const Vec3 centre = t.get<Vec3>("center");
  for (const auto& [k, placed] : {std::pair{"center", norm(centre - box_centre) > 1e-9 * grid_.h()},
                                  std::pair{"rotation_angle", t.get<double>("rotation_angle") != 0}})
    if (placed)
      throw InputError(std::string("membrane[0].") + k + " = " + t.value_text(k) + ": does not apply with " + key +
                       " (the packer places and turns the copies)");
  const Mesh tmpl = meshes_[0];
  const MembraneGeometry g = measure(tmpl, initial_[0]);
  std::vector<Vec3> shape, reference;
  for (const auto& p : initial_[0]) shape.push_back(p - g.centroid);
  for (const auto& p : references_[0]) reference.push_back(p - g.centroid);
  double spacing = 0;  // along the element edges, vertex to mid-side node
  for (const auto& e : tmpl.elements)
    for (const auto& [a, b] : {std::pair{0, 3}, {3, 1}, {1, 4}, {4, 2}, {2, 5}, {5, 0}})
      spacing = std::max(spacing, norm(shape[e[a]] - shape[e[b]]));
  double box = 1;
  for (int a = 0; a < 3; ++a) box *= grid_.length(a);
  PackingRequest request;
  request.count = count > 0 ? static_cast<std::size_t>(count) : static_cast<std::size_t>(std::llround(fraction * box / g.volume));
  if (request.count == 0)
    throw InputError("packing.volume_fraction = " + config_.value_text("packing.volume_fraction") +
                     ": less than one cell of volume " + io::format_number(g.volume) + " m^3 in this box");
  request.seed = static_cast<std::uint64_t>(config_.get<std::int64_t>("packing.seed"));
  const double clearance = config_.get<double>("packing.clearance");
  request.clearance = clearance > 0 ? clearance : 1.1 * grid_.h();
  request.stop_requested = stop_requested;
  const auto t0 = std::chrono::steady_clock::now();
  const CellPacking packing(grid_, shape, spacing, request, key);
  std::ostringstream summary;
  summary << "packing: " << request.count << " copies of membrane[0], volume fraction "
          << static_cast<double>(request.count) * g.volume / box << " (seed " << request.seed << "), in "
          << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() << " s";
  packing_summary_ = summary.str();
  const io::Config& m = config_.entry("membrane", 0);
  meshes_.clear();
  references_.clear();
  initial_.clear();
  membranes_.clear();
  corrected_volume_.clear();
  viscosity_ratio_.clear();
  for (const auto& place : packing.placements()) {
    Mesh mesh = tmpl;
    std::vector<Vec3> X, R;
    for (const auto& p : shape) X.push_back(place.rotation * p + place.translation);
    for (const auto& p : reference) R.push_back(place.rotation * p + place.translation);
    mesh.nodes = X;
    add_membrane(m, std::move(mesh), std::move(X), std::move(R));
  }
}

void Simulation::check_geometry() const {
  const double h = grid_.h();
  for (std::size_t m = 0; m < initial_.size(); ++m) {
    const auto& X = initial_[m];
    try {
      check_nodes_in_domain(grid_, X);
    } catch (const SimulationError& e) {
      throw InputError(membrane_name(m) + " lies outside the box: " + e.what() + unit_hint(config_, m));
    }
    for (int a = 0; a < 3; ++a) {
      if (!grid_.periodic(a)) continue;  // between walls the nodes are checked against the walls
      const auto [lo, hi] =
          std::minmax_element(X.begin(), X.end(), [&](const Vec3& p, const Vec3& q) { return p[a] < q[a]; });
      if ((*hi)[a] - (*lo)[a] >= grid_.length(a)) {
        std::ostringstream s;
        s << membrane_name(m) << " spans " << (*hi)[a] - (*lo)[a] << " m along " << kAxes[a]
          << ": must be shorter than the periodic box (" << grid_.length(a) << " m)" << unit_hint(config_, m);
        throw InputError(s.str());
      }
    }
    if (const auto pair = self_intersection(meshes_[m], X))
      throw InputError(membrane_name(m) + ": its surface intersects itself (elements " + std::to_string(pair->first) +
                       " and " + std::to_string(pair->second) + ")");
    const double d = min_wall_distance(grid_, X);
    if (d < h) {
      std::ostringstream s;
      s << membrane_name(m) << " comes within " << d << " m of a wall: must keep at least one cell (" << h
        << " m) clear for the delta function" << unit_hint(config_, m);
      throw InputError(s.str());
    }
  }
  if (const auto gap = closest_foreign_nodes(grid_, initial_, h)) {
    std::ostringstream s;
    s << membrane_name(gap->membrane_a) << " overlaps or touches " << membrane_name(gap->membrane_b) << ": its node "
      << gap->node_a << " is " << gap->distance << " m from node " << gap->node_b << " of "
      << membrane_name(gap->membrane_b) << ", closer than one cell (" << h << " m)";
    throw InputError(s.str());
  }
  // Without close nodes two closed surfaces are apart or nested: test one node of each against the other.
  std::vector<std::pair<Vec3, Vec3>> boxes;
  for (const auto& X : initial_) {
    Vec3 lo = X[0], hi = X[0];
    for (const auto& p : X)
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
    boxes.emplace_back(lo, hi);
  }
  auto nested = [&](std::size_t inner, std::size_t outer) {
    const auto& [lo, hi] = boxes[outer];
    const Vec3 mid = 0.5 * (lo + hi), p = mid + minimum_image(grid_, initial_[inner][0], mid);
    for (int k = 0; k < 3; ++k)
      if (p[k] < lo[k] || p[k] > hi[k]) return false;
    return encloses(meshes_[outer], initial_[outer], p);
  };
  for (std::size_t m = 0; m < initial_.size(); ++m)
    for (std::size_t o = 0; o < m; ++o) {
      if (nested(m, o)) throw InputError(membrane_name(m) + " lies inside " + membrane_name(o));
      if (nested(o, m)) throw InputError(membrane_name(o) + " lies inside " + membrane_name(m));
    }
}

FluidState Simulation::initial_fluid_state() const {
  FluidState s = fluid_.initial_state();
  const std::string initial = config_.get<std::string>("fluid.initial");
  if (initial == "poiseuille") {
    set_poiseuille_flow(grid_, fluid_.params(), s.u);
    return s;
  }
  if (initial != "couette") return s;
  // The linear profile between the walls of the first wall axis: u = u_lower + (u_upper - u_lower) (x_a - o_a) / L_a.
  const auto& p = fluid_.params();
  int a = -1;
  for (int d = 0; d < 3 && a < 0; ++d)
    if (!grid_.periodic(d)) a = d;
  require(a >= 0, "fluid.initial", "\"rest\" when no axis has walls (\"couette\" needs walls)");
  for (int d = 0; d < 3; ++d) {
    auto& u = s.u[d];
    for (int k = 0; k < u.nz(); ++k)
      for (int j = 0; j < u.ny(); ++j)
        for (int i = 0; i < u.nx(); ++i) {
          const Vec3 x = grid_.face_position(d, i, j, k);
          const double f = (x[a] - grid_.origin()[a]) / grid_.length(a);
          u(i, j, k) = p.wall_lower[a][d] + (p.wall_upper[a][d] - p.wall_lower[a][d]) * f;
        }
  }
  fluid_.apply_wall_values(s.u);
  return s;
}

bool Simulation::finished() const { return time() >= end_time_ * (1 - 1e-12); }

StepRecord Simulation::advance(const std::function<void(const std::string&)>& log,
                               const std::function<bool()>& stop_requested) {
  const auto t0 = std::chrono::steady_clock::now();
  const double remaining = end_time_ - time();
  StepRecord r;
  std::ostringstream where;
  where.precision(10);
  where << "step " << step_ + 1 << ", t = " << time() << ": ";
  try {
    const auto acc = stepper_.advance(*integrator_, *op_, remaining,
                                      [&](const std::string& msg) { log(where.str() + msg); }, stop_requested);
    r.stats = acc.stats;
    r.dt = acc.dt;
    r.rejected = acc.rejected;
    for (std::size_t m = 0; m < corrected_volume_.size(); ++m) {
      if (!corrected_volume_[m]) continue;
      auto X = op_->membrane_positions(m);
      try {
        normal_shift(meshes_[m], X, *corrected_volume_[m]);
      } catch (const SimulationError& e) {
        throw SimulationError(membrane_name(m) + " " + e.what());
      }
      op_->correct_positions(m, X);
    }
  } catch (const SimulationError& e) {
    throw SimulationError(where.str() + e.what());
  }
  ++step_;
  r.step = step_;
  r.time = time();
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  check_stability(r);
  return r;
}

void Simulation::check_stability(const StepRecord& r) const {
  const double vmax = max_speed_;
  for (std::size_t m = 0; m < num_membranes(); ++m) {
    const auto X = op_->membrane_positions(m);
    const auto U = op_->membrane_velocities(m);
    for (std::size_t i = 0; i < X.size(); ++i) {
      const char* what = !isfinite(X[i]) ? "position is not finite"
                         : !isfinite(U[i]) ? "velocity is not finite"
                         : norm(U[i]) > vmax ? "speed exceeds time.max_speed (runaway)"
                                             : nullptr;
      if (!what) continue;
      std::ostringstream s;
      s.precision(10);
      s << "unstable at step " << r.step << ", t = " << r.time << ": " << membrane_name(m) << " node " << i << " "
        << what << " (|u| = " << norm(U[i]) << " m/s, bound " << vmax << ")";
      throw SimulationError(s.str());
    }
  }
  // The fluid everywhere in the box, also where no membrane samples it.
  const FluidState& f = op_->fluid_state();
  auto unstable_at = [&](const Array3& a, std::size_t n, const std::string& what, const std::string& symbol,
                         const char* where) {
    const std::size_t i = n % std::size_t(a.nx()), j = n / std::size_t(a.nx()) % std::size_t(a.ny()),
                      k = n / (std::size_t(a.nx()) * std::size_t(a.ny()));
    std::ostringstream s;
    s.precision(10);
    s << "unstable at step " << r.step << ", t = " << r.time << ": fluid " << what << " at " << where << " (" << i
      << ", " << j << ", " << k << ") ";
    const double v = a.values()[n];
    if (std::isfinite(v))
      s << "exceeds time.max_speed (runaway) (|" << symbol << "| = " << std::abs(v) << " m/s, bound " << vmax << ")";
    else
      s << "is not finite";
    throw SimulationError(s.str());
  };
  for (int d = 0; d < 3; ++d) {
    const auto& u = f.u[d].values();
    for (std::size_t n = 0; n < u.size(); ++n)
      if (!(std::abs(u[n]) <= vmax)) {
        const std::string u_d = std::string("u_") + kAxes[d];
        unstable_at(f.u[d], n, "velocity " + u_d, u_d, "face");
      }
  }
  const auto& p = f.p.values();
  for (std::size_t n = 0; n < p.size(); ++n)
    if (!std::isfinite(p[n])) unstable_at(f.p, n, "pressure", "p", "cell");
}

io::Checkpoint Simulation::checkpoint() const {
  io::Checkpoint ck;
  ck.put_string("config", config_.to_toml_string());
  ck.put_int("step", step_);
  const FluidState& f = op_->fluid_state();
  for (int d = 0; d < 3; ++d) {
    const auto& u = f.u[d];
    const std::vector<std::size_t> shape{std::size_t(u.nz()), std::size_t(u.ny()), std::size_t(u.nx())};
    ck.put_array("fluid.u" + std::to_string(d), u.values(), shape);
    ck.put_array("fluid.adv" + std::to_string(d), f.adv[d].values(), shape);
    // u^{n-1}, which a variable viscosity extrapolates from (absent before the first step and without one).
    if (f.u_prev[d].size() == u.size()) ck.put_array("fluid.u_prev" + std::to_string(d), f.u_prev[d].values(), shape);
  }
  ck.put_array("fluid.p", f.p.values(), {std::size_t(f.p.nz()), std::size_t(f.p.ny()), std::size_t(f.p.nx())});
  ck.put_array("fluid.p_prev", f.p_prev.values(),
               {std::size_t(f.p_prev.nz()), std::size_t(f.p_prev.ny()), std::size_t(f.p_prev.nx())});
  ck.put_double("fluid.dt_prev", f.dt_prev);
  ck.put_double("fluid.dt_prev2", f.dt_prev2);
  ck.put_int("fluid.step", f.step);
  ck.put_double("fluid.time", f.time);
  for (std::size_t m = 0; m < num_membranes(); ++m) {
    const auto X = op_->membrane_positions(m);
    ck.put_array(membrane_name(m) + ".positions", {&X[0].x, &X[0].x + 3 * X.size()}, {X.size(), 3});
    const auto& R = references_[m];
    ck.put_array(membrane_name(m) + ".reference", {&R[0].x, &R[0].x + 3 * R.size()}, {R.size(), 3});
  }
  ck.put_array("integrator.previous_positions", integrator_->previous_positions());
  ck.put_double("integrator.previous_dt", integrator_->previous_dt());
  ck.put_array("integrator.guess_errors", integrator_->guess_errors().errors());
  ck.put_double("stepper.dt", stepper_.dt());
  ck.put_int("stepper.successes", stepper_.successes());
  return ck;
}

void Simulation::restore(const io::Checkpoint& ck) {
  // The checkpoint's configuration must be this one, up to the keys a continued or branched run may change and
  // the names of mesh files (a run folder's copy stands for its original; what the files hold is compared with
  // the reference state below).
  io::Config theirs = config_.schema().parse_string(ck.get_string("config"), "checkpoint");
  leave_out_inapplicable(theirs);
  const auto may_change = [](const std::string& key) {
    return key == "time.end" || key == "scenario.kt_end" || key.starts_with("output.") || key.starts_with("solver.") ||
           key == "mesh.file" || key == "mesh.reference_file";
  };
  const auto differ = [&](const std::string& key, const std::string& was, const std::string& is) {
    throw InputError(key + " = " + is + ": the checkpoint " + ck.source() + " was written with " + key + " = " + was +
                     " (on restart only time.end, scenario.kt_end, [output] and [solver] keys may change)");
  };
  for (const auto& k : config_.schema().keys())
    if (!may_change(k.key) && theirs.value_text(k.key) != config_.value_text(k.key))
      differ(k.key, theirs.value_text(k.key), config_.value_text(k.key));
  for (const auto& t : config_.schema().table_arrays()) {
    if (theirs.count(t.name) != config_.count(t.name))
      differ("[[" + t.name + "]] count", std::to_string(theirs.count(t.name)), std::to_string(config_.count(t.name)));
    for (std::size_t i = 0; i < config_.count(t.name); ++i)
      for (const auto& k : config_.entry(t.name, i).schema().keys()) {
        if (may_change(k.key)) continue;
        const std::string was = theirs.entry(t.name, i).value_text(k.key), is = config_.entry(t.name, i).value_text(k.key);
        if (was != is) differ(t.name + "[" + std::to_string(i) + "]." + k.key, was, is);
      }
  }
  // Every entry is checked before it is used, so that a damaged checkpoint whose checksum was recomputed is
  // refused by name instead of failing later in the run.
  auto number = [&](const std::string& name, double v, bool ok, const std::string& allowed) {
    if (ok) return v;
    std::ostringstream s;
    s << "= " << v << ": must be " << allowed;
    ck.invalid(name, s.str());
  };
  auto count = [&](const std::string& name) {
    const std::int64_t v = ck.get_int(name);
    number(name, double(v), v >= 0, "an integer >= 0");
    return v;
  };
  auto time_value = [&](const std::string& name) {
    const double v = ck.get_double(name);
    return number(name, v, std::isfinite(v) && v >= 0, "a finite number >= 0");
  };
  auto array = [&](const std::string& name, std::size_t size) -> const std::vector<double>& {
    const auto& values = ck.array(name);
    if (values.size() != size)
      ck.invalid(name, "has " + std::to_string(values.size()) + " values, this configuration needs " +
                           std::to_string(size));
    for (std::size_t i = 0; i < values.size(); ++i)
      if (!std::isfinite(values[i]))
        ck.invalid(name, "has a value that is not finite (index " + std::to_string(i) + ")");
    return values;
  };
  FluidState f = fluid_.initial_state();
  for (int d = 0; d < 3; ++d) {
    const std::size_t n = f.u[d].values().size();
    f.u[d].values() = array("fluid.u" + std::to_string(d), n);
    f.adv[d].values() = array("fluid.adv" + std::to_string(d), n);
    const std::string prev = "fluid.u_prev" + std::to_string(d);
    if (ck.has(prev)) {
      if (f.u_prev[d].size() != n) f.u_prev[d] = f.u[d];
      f.u_prev[d].values() = array(prev, n);
    }
  }
  f.p.values() = array("fluid.p", f.p.values().size());
  f.dt_prev = time_value("fluid.dt_prev");
  // Checkpoints written before fluid.pressure have no p^{n-3/2}: an extrapolating run then lags for one step.
  if (ck.has("fluid.p_prev")) {
    f.p_prev.values() = array("fluid.p_prev", f.p_prev.values().size());
    f.dt_prev2 = time_value("fluid.dt_prev2");
  }
  f.step = count("fluid.step");
  f.time = time_value("fluid.time");
  std::vector<std::vector<Vec3>> X(num_membranes());
  std::size_t unknowns = 0;
  for (std::size_t m = 0; m < num_membranes(); ++m) {
    const auto& R = references_[m];
    if (ck.array(membrane_name(m) + ".reference") != std::vector<double>(&R[0].x, &R[0].x + 3 * R.size()))
      throw InputError("checkpoint: the reference state of " + membrane_name(m) +
                       " differs from the one this configuration builds (was its mesh file changed?)");
    const auto& a3 = array(membrane_name(m) + ".positions", 3 * R.size());
    X[m].resize(a3.size() / 3);
    for (std::size_t i = 0; i < X[m].size(); ++i) X[m][i] = {a3[3 * i], a3[3 * i + 1], a3[3 * i + 2]};
    unknowns += a3.size();
  }
  const std::string previous = "integrator.previous_positions";
  const auto& prev_X = array(previous, ck.array(previous).empty() ? 0 : unknowns);
  const double prev_dt = time_value("integrator.previous_dt");
  // Checkpoints written before the initial-guess recurrence have no guess errors: it then starts afresh.
  const std::string errors = "integrator.guess_errors";
  const std::vector<double> guess_errors =
      ck.has(errors) ? array(errors, ck.array(errors).size()) : std::vector<double>{};
  const double nominal = config_.get<double>("time.dt"), dt = ck.get_double("stepper.dt");
  number("stepper.dt", dt, std::isfinite(dt) && dt > 0 && dt <= nominal, "in (0, time.dt]");
  const std::int64_t successes = count("stepper.successes");
  const std::int64_t step = count("step");
  const double end = config_.get<double>("time.end");
  if (f.time >= end * (1 - 1e-12)) {
    std::ostringstream s;
    s << "time.end = " << end << ": must be later than the time of the checkpoint " << ck.source() << ", t = "
      << f.time << " (nothing left to run)";
    throw InputError(s.str());
  }
  std::vector<const ElasticMembrane*> ms;
  for (auto& m : membranes_) ms.push_back(m.get());
  op_ = std::make_unique<ImmersedBoundaryOperator>(fluid_, coupler_, ms, X, std::move(f), make_contact(config_),
                                                   viscosity_ratio_);
  integrator_->set_history(prev_X, prev_dt, guess_errors);
  stepper_.set_state(dt, static_cast<int>(successes));
  step_ = step;
}

}  // namespace immerse
