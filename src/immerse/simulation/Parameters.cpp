#include "immerse/simulation/Parameters.hpp"

#include <map>
#include <set>
#include <string>

#include "immerse/timestep/MembraneIntegrator.hpp"

namespace immerse {

using io::ConfigSchema;
using io::Range;

namespace {

ConfigSchema membrane_schema() {
  ConfigSchema m;
  m.add_string("shape", "sphere", {"sphere", "ellipsoid", "oblate", "rbc"},
               "initial shape: sphere (radius), ellipsoid (semi_axes, eq. 43), oblate spheroid (radius of the "
               "equal-volume sphere, aspect_ratio, inclination; §4.2.2) or biconcave red blood cell (eq. 45, R0)");
  m.add_double("radius", 1e-6, Range::positive(),
               "sphere radius / radius of the equal-volume sphere (m); with mesh.family = \"file\" only in the shear "
               "scenarios, as the radius a of their groups G and Re");
  m.add_vec3("semi_axes", {1e-6, 1e-6, 1e-6}, Range::positive(), "ellipsoid semi-axes along x, y, z (m)");
  m.add_double("aspect_ratio", 1.0, Range::open_closed(0, 1), "oblate spheroid: short over long axis b/a");
  m.add_double("inclination", 0.0, Range::closed(-3.2, 3.2), "oblate spheroid: angle of the long axis from x towards z (rad)");
  m.add_double("R0", 3.91e-6, Range::positive(), "red blood cell radius R0 of eq. (45) (m)");
  m.add_string("reference", "initial", {"initial", "sphere", "file"},
               "stress-free reference configuration: the initial shape, a sphere of reference_radius (§4.1), or "
               "the shape of mesh.reference_file (mesh.family = \"file\")");
  m.add_double("reference_radius", 1e-6, Range::positive(), "radius of the reference sphere when reference = \"sphere\" (m)");
  m.add_vec3("center", {0, 0, 0}, Range::any(), "position of the shape's centre (m)");
  m.add_vec3("rotation_axis", {0, 0, 1}, Range::any(), "axis of the rigid rotation applied to the shape");
  m.add_double("rotation_angle", 0.0, Range::closed(-7, 7), "angle of the rigid rotation (rad)");
  m.add_string("mesh.family", "icosahedral", {"icosahedral", "octahedral", "file"},
               "subdivided icosahedron (10*4^(l+1)+2 nodes) or octahedron (4*4^(l+1)+2 nodes) mapped onto the shape, "
               "or a Gmsh file (mesh.file, 6- or 3-node triangles: the initial shape itself, scaled by mesh.scale and "
               "placed by center and rotation; shape, radius, semi_axes, aspect_ratio, inclination, R0 and mesh.level "
               "do not apply)");
  m.add_int("mesh.level", 3, Range::closed(0, 7), "subdivision level (icosahedral 4: 10,242 nodes; octahedral 5: 16,386)");
  m.add_path("mesh.file",
             "Gmsh .msh file of one closed surface when mesh.family = \"file\"; a relative name is taken from the "
             "configuration file's folder (given with --set: from the current folder); the run folder keeps a copy");
  m.add_double("mesh.scale", 1.0, Range::positive(),
               "mesh.family = \"file\": metres per length unit of the file (1e-6 for a mesh in micrometres), applied "
               "before center and rotation");
  m.add_path("mesh.reference_file",
             "reference = \"file\": Gmsh .msh file of the stress-free shape, the same nodes and elements as mesh.file "
             "in another shape; scaled and placed as mesh.file, found and copied as it is");
  m.add_string("law", "neo_hookean", {"neo_hookean", "yeoh", "skalak"}, "strain energy: eq. (22), (23) or (24)");
  m.add_double("Es", 1e-6, Range::positive(), "neo-Hookean surface elastic modulus E_s of eq. (22) (N/m)");
  m.add_double("C10", 2.5e-6, Range::positive(), "Yeoh C10 of eq. (23) (N/m)");
  m.add_double("C30", 1.7e-7, Range::positive(), "Yeoh C30 of eq. (23) (N/m)");
  m.add_double("C11", 5e-6, Range::positive(), "Skalak C11 of eq. (24) (N/m)");
  m.add_double("C21", 5e-4, Range::positive(), "Skalak C21 of eq. (24) (N/m)");
  m.add_double("dilation_modulus", 0.0, Range::non_negative(),
               "K_D of the local area dilation energy W_D = (K_D/2) (ln J)^2 added to the law at every quadrature "
               "point, J the local area ratio (N/m: adds K_D to the small-strain area modulus; its compressive tension "
               "K_D ln J / J grows without bound as J -> 0; src/immerse/membrane/AreaDilation.hpp); 0 switches it off");
  m.add_double("kappa_B", 0.0, Range::non_negative(), "bending modulus kappa_B of eq. (25) and of the bending energy (J); 0 switches bending off");
  m.add_string("bending_reference", "zero", {"zero", "rest"},
               "reference mean curvature of eq. (25): zero (flat rest state, §4.2.3) or that of the reference shape");
  m.add_string("force", "energy", {"energy", "contour"},
               "nodal forces: -dE/dX of the in-plane energy and the discrete mean-curvature bending energy (energy "
               "stable: a membrane at rest cannot gain energy), or the paper's contour integral of eq. (42) with the "
               "bending moments of eq. (25)");
  m.add_double("volume_modulus", 0.0, Range::non_negative(),
               "k_V of the global volume constraint E_V = k_V (V - V0)^2 / (2 V0), V0 the initial volume (Pa: k_V dV/V0 "
               "is the pressure jump it adds); 0 switches it off (docs/volume-conservation.md)");
  m.add_double("area_modulus", 0.0, Range::non_negative(),
               "k_A of the global area constraint E_A = k_A (A - A0)^2 / (2 A0), A0 the initial area (N/m: k_A dA/A0 "
               "is the isotropic tension it adds); 0 switches it off");
  m.add_double("viscosity_ratio", 1.0, Range::closed(0.1, 10),
               "viscosity ratio lambda = mu_in / mu_out of the fluid inside this membrane to fluid.mu outside; 1: the "
               "same fluid (docs/viscosity-contrast.md)");
  m.add_string("volume_correction", "none", {"none", "normal_shift"},
               "after each accepted step: nothing, or move all nodes along their normals by one common distance "
               "that restores the initial volume exactly (the fluid is not changed; docs/volume-conservation.md)");
  return m;
}

ConfigSchema wall_schema() {
  ConfigSchema w;
  w.add_string("shape", "tube", {"tube", "sphere", "box", "constriction", "surface"},
               "tube: the fluid inside a circular cylinder (radius, center, axis), everything outside it wall; sphere: "
               "a solid ball (radius, center); box: an axis-aligned box (center, size, inside), a solid block or a "
               "rectangular channel; constriction: a rectangular channel along a coordinate axis narrowed over a "
               "length (center, axis, size, throat); surface: a closed triangulated surface read from a file (file, "
               "scale, inside) (src/immerse/walls/WallGeometry.hpp, WallSurface.hpp)");
  w.add_double("radius", 1e-6, Range::positive(), "radius of the tube or sphere (m)");
  w.add_vec3("center", {0, 0, 0}, Range::any(),
             "a point on the tube's axis, the sphere's or box's centre, or the centre of the constriction's throat (m); "
             "in the box");
  w.add_vec3("axis", {0, 0, 1}, Range::any(),
             "tube: direction of its axis, along (mx Lx, my Ly, mz Lz) with whole numbers m, so that the tube closes on "
             "itself across the periodic box ([0, 0, 1]: along z; [1, 0, 2] in a box with Lz = Lx: at 26.6 degrees); "
             "constriction: the channel's axis, [1, 0, 0], [0, 1, 0] or [0, 0, 1]");
  w.add_vec3("size", {1e-6, 1e-6, 1e-6}, Range::positive(),
             "box: its edge lengths (m), an edge at least the box's length making it span that periodic axis (with "
             "inside = \"fluid\": a rectangular channel along it); constriction: the channel's widths across its axis "
             "(m; the component along the axis is not used: the channel runs across the periodic box)");
  w.add_vec3("throat", {5e-7, 5e-7, 5e-7}, Range::positive(),
             "constriction: the throat's widths across the axis, at most the channel's and below them along at least "
             "one axis, and its length along the axis, below the box's (m)");
  w.add_path("file",
             "surface: STL (ASCII or binary) file of one or more, or Gmsh .msh file of one, closed, consistently "
             "oriented, non-self-intersecting triangulated surfaces, in the box's coordinates times scale (periodic "
             "images included); a relative name is taken from the configuration file's folder (given with --set: from the "
             "current folder); the run folder keeps a copy");
  w.add_double("scale", 1.0, Range::positive(), "surface: metres per length unit of the file (1e-6 for micrometres)");
  w.add_string("inside", "solid", {"solid", "fluid"},
               "box, surface: what the box or the closed surface encloses: a solid obstacle (the fluid outside it), or "
               "the fluid (a channel; everything outside it wall)");
  return w;
}

}  // namespace

ConfigSchema run_schema() {
  ConfigSchema s;
  s.add_string("scenario.kind", "custom",
               {"custom", "none", "oscillating_membrane", "capsule_shear", "oblate_shear", "bending_shear",
                "rbc_stretch", "rbc_channel", "suspension_shear", "tube_flow", "capsule_constriction"},
               "custom: your own experiment, every value as given (\"none\" is its former name); otherwise an experiment "
               "of the paper whose nondimensional groups below set the dimensional values the file leaves unset "
               "(see scenarios/README.md)");
  s.add_double("scenario.G", 0.05, Range::positive(), "capillary number G = mu k a / E_s of eq. (44) (shear scenarios)");
  s.add_double("scenario.Re", 1e-3, Range::positive(), "Reynolds number Re = rho k a^2 / mu (shear scenarios)");
  s.add_double("scenario.kappa_B_hat", 0.0, Range::non_negative(), "reduced bending modulus kappa_B / (a^2 E_s) (§4.2.3)");
  s.add_double("scenario.aspect_ratio", 1.0, Range::open_closed(0, 1), "oblate_shear: initial aspect ratio b/a (§4.2.2)");
  s.add_double("scenario.theta0", 0.0, Range::closed(-3.2, 3.2), "oblate_shear: initial inclination (rad)");
  s.add_double("scenario.mu0", 7.3e-6, Range::positive(),
               "rbc_stretch, rbc_channel: in-plane shear modulus mu0 (N/m); Yeoh law with C10 = mu0/2, C30 = mu0/30 (§4.3)");
  s.add_double_list("scenario.copies", {1, 1, 1}, Range::at_least(1),
                    "rbc_channel: copies of the 32-cell arrangement along x, y and z (three whole numbers); the box "
                    "holds cx x cy x cz copies of the arrangement, each in a sub-box of size (Lx/cx, Ly/cy, Lz/cz)");
  s.add_double_list("scenario.forces_pN", {0, 20, 40, 60, 80, 100, 120, 140, 160, 180, 200}, Range::non_negative(),
                    "rbc_stretch: the stretching forces of the sweep (pN), each run to steady state");
  s.add_double("scenario.patch_um", 2.0, Range::positive(),
               "rbc_stretch: diameter of the two contact patches at the ends of the diameter along x (um)");
  s.add_double("scenario.steady_tol", 1e-4, Range::open(0, 1),
               "rbc_stretch: steady when both diameters change by less than this (relative) over one relaxation time");
  s.add_double("scenario.max_relaxation_times", 200.0, Range::positive(),
               "rbc_stretch: give up waiting for a steady state after this many relaxation times per force");
  s.add_double("scenario.k_dt", 0.01, Range::positive(), "shear scenarios: time step in units of 1/k");
  s.add_double("scenario.kt_end", 10.0, Range::positive(), "shear scenarios: end time in units of 1/k");

  s.add_double("domain.Lx", 1e-5, Range::positive(), "box length along x (m)");
  s.add_double("domain.Ly", 1e-5, Range::positive(), "box length along y (m)");
  s.add_double("domain.Lz", 1e-5, Range::positive(), "box length along z (m)");
  s.add_vec3("domain.origin", {0, 0, 0}, Range::any(), "lower corner of the box (m)");
  s.add_int("grid.nx", 32, Range::at_least(2), "cells along x (cells are cubic: Lx/nx = Ly/ny = Lz/nz)");
  s.add_int("grid.ny", 32, Range::at_least(2), "cells along y");
  s.add_int("grid.nz", 32, Range::at_least(2), "cells along z");
  for (const char* a : {"x", "y", "z"}) {
    const std::string axis = a;
    s.add_string("boundary." + axis, "periodic", {"periodic", "wall"}, "boundary along " + axis + ": periodic or two no-slip walls");
    s.add_vec3("boundary." + axis + "_lower_velocity", {0, 0, 0}, Range::any(),
               "velocity of the wall at the lower end of " + axis + " (m/s)");
    s.add_vec3("boundary." + axis + "_upper_velocity", {0, 0, 0}, Range::any(),
               "velocity of the wall at the upper end of " + axis + " (m/s)");
  }
  s.add_double("fluid.rho", 1000.0, Range::positive(), "density (kg/m^3)");
  s.add_double("fluid.mu", 1e-3, Range::positive(), "dynamic viscosity (Pa s)");
  s.add_vec3("fluid.body_force", {0, 0, 0}, Range::any(), "uniform body force, a mean pressure gradient (N/m^3)");
  s.add_vec3("fluid.flow_rate", {0, 0, 0}, Range::any(),
             "volume flow rate through the box's cross-section (m^3/s) along one periodic axis, held exactly at every "
             "step by a uniform body force added along it to fluid.body_force (the step's response to a unit body "
             "force, scaled; the diagnostics' pressure_drop and P_body include it); 0 switches it off");
  s.add_string("fluid.initial", "rest", {"rest", "couette", "poiseuille"},
               "initial velocity: at rest, the linear (Couette) profile between the moving walls, or the steady "
               "flow driven by fluid.body_force between resting walls (the discrete Poiseuille solution)");

  s.add_string("fluid.pressure", "lagged", {"lagged", "extrapolated"},
               "pressure in the momentum step (9): lagged, p^{n-1/2} as printed (first order in time where the fluid "
               "is a Stokes flow at the step's scale, nu dt / h^2 >> 1, as in the red-cell channel), or extrapolated "
               "to t^{n+1/2} from the last two pressures (second order there too)");
  s.add_string("fluid.fft_planning", "estimate", {"estimate", "measure"},
               "FFTW plans of the fast solvers: estimate (the same plans in every run: results bitwise reproducible "
               "across runs, restarts and thread counts) or measure (FFTW times candidate plans: the fluid step "
               "5-20 % faster, but the choice and so the round-off may differ from run to run)");

  s.add_string("coupling.kernel", "roma3", {"roma3", "peskin4"},
               "discrete delta: Roma-Peskin-Berger 3-point of eq. (8), or Peskin's 4-point");

  s.add_double("contact.range", 0.0, Range::non_negative(),
               "range d of the repulsion between membranes and from the walls (m; docs/contact.md): nodes of two "
               "membranes closer than d, or a node closer than d to a wall, push apart with a force rising from zero "
               "at d; when not given, the grid spacing h (derived); 0 switches contact off");
  s.add_double("contact.strength", 1.0, Range::positive(),
               "contact force scale eps (dimensionless): the largest force of one pair of nodes is eps K_s d, with "
               "K_s the small-strain area modulus of the membranes (N/m; neo-Hookean E_s, Yeoh 6 C10, Skalak "
               "C11/2 + C21; without dilation_modulus)");
  s.add_bool("contact.walls", true, "repel the nodes from the no-slip walls as well (contact.range > 0)");

  s.add_string("time.scheme", "jfnk", integrator_names(),
               "membrane update: jfnk (§2.4.3), lbfgs, bfgs (eq. 35, small meshes), euler (eq. 28), rk2, anderson "
               "(Anderson acceleration of the implicit update: fewer fluid solves than jfnk on soft cells, §4.4; "
               "jfnk on stiff ones)");
  s.add_double("time.dt", 1e-4, Range::positive(), "time step (s)");
  s.add_double("time.end", 1e-2, Range::positive(), "end time (s)");
  s.add_double("time.theta", 0.5, Range::closed(0.5, 1.0),
               "theta-method weight of the implicit update: 0.5 trapezoidal (eq. 29), 1 backward Euler (L-stable)");
  s.add_double("time.dt_min", 1e-12, Range::positive(), "floor of the step-halving on a failed nonlinear solve (s)");
  s.add_double("time.max_speed", 1e3, Range::positive(),
               "runaway bound: a node velocity above it stops the run as unstable (m/s)");

  s.add_double("solver.newton_rtol", 1e-8, Range::open(0, 1), "Newton stop ||g|| / ||X|| (§4: 1e-8)");
  s.add_double("solver.gmres_rtol", 1e-3, Range::open(0, 1), "relative tolerance of each GMRES solve (§4: 1e-3)");
  s.add_int("solver.max_newton_its", 20, Range::at_least(1), "nonlinear iterations before a step is rejected and halved");
  s.add_int("solver.bfgs_memory", 20, Range::at_least(1), "stored pairs of the limited-memory quasi-Newton");
  s.add_int("solver.anderson_memory", 5, Range::at_least(1),
            "time.scheme = anderson: the depth m, the number of past residuals mixed");
  s.add_double("solver.anderson_beta", 0.85, Range::open_closed(0, 2),
               "time.scheme = anderson: the mixing parameter beta of the fixed-point map X - beta g(X)");
  s.add_string("solver.initial_guess", "recurrence", {"recurrence", "extrapolation"},
               "Newton's start: the linear extrapolation of §3 step 1 plus the error a recurrence fitted to the last "
               "steps' errors predicts (recurrence), or the extrapolation alone (extrapolation, the paper's)");
  s.add_string("solver.petsc_options", "", {},
               "PETSc options of the implicit schemes' solver (jfnk: SNES, KSP, PC, MatMFFD; anderson, lbfgs: SNES) "
               "and of PETSc itself (-log_view, -options_left), e.g. \"-ksp_gmres_restart 50 -snes_converged_reason\"; "
               "they win over the environment variable PETSC_OPTIONS, both over the solver.* settings; an option no "
               "object used stops the run after its first solve (exit 2; user guide, PETSc options)");

  s.add_int("output.diagnostics_every", 1, Range::at_least(1), "steps between rows of diagnostics.csv");
  s.add_int("output.fields_every", 0, Range::at_least(0), "steps between ParaView frames (XDMF + HDF5); 0: none");
  s.add_bool("output.fluid_fields", true, "include the fluid (velocity, pressure, vorticity) in the ParaView frames");
  s.add_int("output.checkpoint_every", 0, Range::at_least(0), "steps between checkpoints; 0: only at the end");
  s.add_double("output.log_seconds", 10.0, Range::positive(), "wall-clock seconds between log lines when not on a terminal");

  s.add_double("packing.volume_fraction", 0.0, Range::closed(0, 0.7),
               "fill the box to this volume fraction with copies of membrane[0] at random positions and orientations "
               "(src/immerse/contact/CellPacking.hpp); 0: the [[membrane]] entries as given");
  s.add_int("packing.count", 0, Range::at_least(0), "place this many copies of membrane[0] instead (0: none)");
  s.add_int("packing.seed", 1, Range::at_least(0), "seed of the random positions and orientations");
  s.add_double("packing.clearance", 0.0, Range::non_negative(),
               "least distance between nodes of two copies and from a node to a wall (m); 0: 1.1 grid spacings");
  s.add_table_array("membrane", membrane_schema(), 0, "the membranes (capsules, cells), one [[membrane]] table each");
  s.add_table_array("wall", wall_schema(), 0,
                    "rigid no-slip walls of any shape inside a box periodic along every axis, one [[wall]] table each; "
                    "the wall is the union of their solids (fluid/GhostCellWalls.hpp)");
  return s;
}

bool is_shear_kind(const std::string& kind) {
  return kind == "capsule_shear" || kind == "oblate_shear" || kind == "bending_shear";
}

std::string membrane_key_not_applying(const io::Config& m, const std::string& key, bool shear) {
  const std::string reference = m.get<std::string>("reference");
  if (m.get<std::string>("mesh.family") != "file")
    return key == "mesh.file" || key == "mesh.scale" || key == "mesh.reference_file"
               ? "does not apply unless mesh.family = \"file\""
               : "";
  if (key == "shape" || key == "semi_axes" || key == "aspect_ratio" || key == "inclination" || key == "R0" ||
      (key == "radius" && !shear))
    return "does not apply to mesh.family = \"file\" (the file gives the shape; use mesh.scale)";
  if (key == "mesh.level") return "does not apply to mesh.family = \"file\" (the file gives the nodes)";
  if (key == "reference_radius" && reference != "sphere") return "does not apply unless reference = \"sphere\"";
  if (key == "mesh.reference_file" && reference != "file") return "does not apply unless reference = \"file\"";
  return "";
}

std::string wall_key_not_applying(const io::Config& w, const std::string& key) {
  const std::string shape = w.get<std::string>("shape");
  if (key == "shape") return "";
  static const std::map<std::string, std::set<std::string>> keys{
      {"tube", {"radius", "center", "axis"}},
      {"sphere", {"radius", "center"}},
      {"box", {"center", "size", "inside"}},
      {"constriction", {"center", "axis", "size", "throat"}},
      {"surface", {"file", "scale", "inside"}}};
  const auto& own = keys.at(shape);
  if (own.contains(key)) return "";
  std::string list;
  for (const std::string& k : own) list += (list.empty() ? "" : ", ") + k;
  return "does not apply to shape = \"" + shape + "\" (its keys: " + list + ")";
}

void leave_out_inapplicable(io::Config& config) {
  const bool shear = is_shear_kind(config.get<std::string>("scenario.kind"));
  for (std::size_t i = 0; i < config.count("membrane"); ++i) {
    const std::string p = "membrane[" + std::to_string(i) + "].";
    for (const auto& key : config.entry("membrane", i).schema().keys())
      if (!membrane_key_not_applying(config.entry("membrane", i), key.key, shear).empty()) config.leave_out(p + key.key);
  }
  for (std::size_t i = 0; i < config.count("wall"); ++i) {
    const std::string p = "wall[" + std::to_string(i) + "].";
    for (const auto& key : config.entry("wall", i).schema().keys())
      if (!wall_key_not_applying(config.entry("wall", i), key.key).empty()) config.leave_out(p + key.key);
  }
}

}  // namespace immerse
