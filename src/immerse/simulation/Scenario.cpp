#include "immerse/simulation/Scenario.hpp"

#include <cstdio>
#include <string>
#include <vector>

#include "immerse/core/Error.hpp"

namespace immerse {

namespace {
std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}
bool is_shear(const std::string& kind) {
  return kind == "capsule_shear" || kind == "oblate_shear" || kind == "bending_shear";
}
}  // namespace

double shear_rate(const io::Config& c) {
  if (!is_shear(c.get<std::string>("scenario.kind"))) return 0.0;
  const double a = c.get<double>("membrane[0].radius");
  return c.get<double>("scenario.Re") * c.get<double>("fluid.mu") / (c.get<double>("fluid.rho") * a * a);
}

std::vector<Vec3> channel_cell_centres(const io::Config& c) {
  const Vec3 o = c.get<Vec3>("domain.origin");
  const double Lx = c.get<double>("domain.Lx"), Ly = c.get<double>("domain.Ly"), Lz = c.get<double>("domain.Lz");
  std::vector<Vec3> centres;
  for (int k = 0; k < 5; ++k)
    for (double x : {0.25, 0.75}) centres.push_back({x * Lx, (k + 0.25) * Ly / 5, 0.18 * Lz});
  for (int k = 0; k < 4; ++k) {
    for (double x : {0.2, 0.8}) centres.push_back({x * Lx, (k + 0.125) * Ly / 4, 0.5 * Lz});
    centres.push_back({0.5 * Lx, (k + 0.625) * Ly / 4, 0.5 * Lz});
  }
  for (int k = 0; k < 5; ++k)
    for (double x : {0.25, 0.75}) centres.push_back({x * Lx, (k + 0.75) * Ly / 5, 0.82 * Lz});
  for (auto& p : centres) p += o;
  return centres;
}

namespace {

// Writes the derived values into their keys; one out of range (an extreme group overflowing or underflowing) is
// reported as the scenario's, naming the keys it came from.
io::Config with_derived(const io::Config& config, const std::vector<std::string>& set, const std::string& kind,
                        const std::string& sources) {
  io::Config derived = config;
  try {
    config.schema().apply_overrides(derived, set);
  } catch (const InputError& e) {
    std::string m = e.what();
    if (m.rfind("--set: ", 0) == 0) m = m.substr(7);
    throw InputError("scenario.kind = \"" + kind + "\" derives " + m + " (from " + sources + ")");
  }
  return derived;
}

// The dimensional values the scenario kind implies, written into their keys.
io::Config derive(const io::Config& config) {
  const std::string kind = config.get<std::string>("scenario.kind");
  if (kind == "rbc_stretch" || kind == "rbc_channel") {
    if (config.count("membrane") != 1)
      throw InputError("scenario.kind = \"" + kind + "\": needs exactly one [[membrane]] (" +
                       (kind == "rbc_channel" ? "the template of every cell" : "the cell") + "), given " +
                       std::to_string(config.count("membrane")));
    const double mu0 = config.get<double>("scenario.mu0");
    io::Config derived =
        with_derived(config,
                     {"membrane[0].shape=\"rbc\"", "membrane[0].law=\"yeoh\"", "membrane[0].C10=" + num(mu0 / 2),
                      "membrane[0].C30=" + num(mu0 / 30)},
                     kind, "scenario.mu0");
    if (kind == "rbc_stretch") return derived;
    for (const auto& [axis, bc] : {std::pair{"x", "wall"}, {"y", "periodic"}, {"z", "wall"}})
      require(config.get<std::string>(std::string("boundary.") + axis) == bc, std::string("boundary.") + axis,
              std::string("\"") + bc + "\" for scenario.kind = \"rbc_channel\" (flow along the periodic y axis)");
    const io::Config& cell = derived.entry("membrane", 0);
    const auto centres = channel_cell_centres(config);
    std::vector<std::string> set;
    for (std::size_t i = 0; i < centres.size(); ++i) {
      const std::string prefix = "membrane[" + std::to_string(i) + "].";
      if (i > 0)
        for (const auto& key : cell.schema().keys()) set.push_back(prefix + key.key + "=" + cell.value_text(key.key));
      const Vec3& p = centres[i];
      set.push_back(prefix + "center=[" + num(p.x) + "," + num(p.y) + "," + num(p.z) + "]");
    }
    return with_derived(derived, set, kind, "membrane[0] and the domain");
  }
  if (!is_shear(kind)) return config;
  if (config.count("membrane") != 1) throw InputError("scenario.kind = \"" + kind + "\": needs exactly one [[membrane]]");
  require(config.get<std::string>("boundary.z") == "wall", "boundary.z", "\"wall\" for scenario.kind = \"" + kind + "\"");
  const double a = config.get<double>("membrane[0].radius"), mu = config.get<double>("fluid.mu");
  const double k = shear_rate(config), Es = mu * k * a / config.get<double>("scenario.G");
  const double Lz = config.get<double>("domain.Lz");
  const Vec3 o = config.get<Vec3>("domain.origin");
  const Vec3 centre = {o.x + 0.5 * config.get<double>("domain.Lx"), o.y + 0.5 * config.get<double>("domain.Ly"),
                       o.z + 0.5 * Lz};
  std::vector<std::string> set = {
      "membrane[0].law=\"neo_hookean\"",
      "membrane[0].Es=" + num(Es),
      "membrane[0].kappa_B=" + num(config.get<double>("scenario.kappa_B_hat") * a * a * Es),
      "membrane[0].center=[" + num(centre.x) + "," + num(centre.y) + "," + num(centre.z) + "]",
      "boundary.z_lower_velocity=[" + num(-0.5 * k * Lz) + ",0,0]",
      "boundary.z_upper_velocity=[" + num(0.5 * k * Lz) + ",0,0]",
      "fluid.initial=\"couette\"",
      "time.dt=" + num(config.get<double>("scenario.k_dt") / k),
      "time.end=" + num(config.get<double>("scenario.kt_end") / k),
  };
  if (kind == "oblate_shear") {
    set.push_back("membrane[0].shape=\"oblate\"");
    set.push_back("membrane[0].aspect_ratio=" + num(config.get<double>("scenario.aspect_ratio")));
    set.push_back("membrane[0].inclination=" + num(config.get<double>("scenario.theta0")));
  }
  return with_derived(config, set, kind,
                      "scenario.G, scenario.Re, scenario.k_dt, scenario.kt_end, fluid.mu, fluid.rho, membrane[0].radius");
}

}  // namespace

io::Config apply_scenario(const io::Config& config) {
  const io::Config derived = derive(config);
  // A step longer than the whole run is a mistake in one of the two (the run would silently take one short step).
  const double dt = derived.get<double>("time.dt"), end = derived.get<double>("time.end");
  if (dt > end) {
    const bool shear = is_shear(config.get<std::string>("scenario.kind"));
    const std::string step = shear ? "scenario.k_dt" : "time.dt", stop = shear ? "scenario.kt_end" : "time.end";
    const double a = shear ? config.get<double>("scenario.k_dt") : dt;
    const double b = shear ? config.get<double>("scenario.kt_end") : end;
    throw InputError(step + " = " + num(a) + ": must be <= " + stop + " = " + num(b) + " (one step is longer than the run)");
  }
  // A wall velocity on a periodic axis would be ignored: there is no wall to move.
  for (const std::string axis : {"x", "y", "z"}) {
    if (derived.get<std::string>("boundary." + axis) != "periodic") continue;
    for (const std::string side : {"_lower_velocity", "_upper_velocity"}) {
      const std::string key = "boundary." + axis + side;
      if (const Vec3 v = derived.get<Vec3>(key); v.x != 0 || v.y != 0 || v.z != 0)
        throw InputError(key + " = " + derived.value_text(key) + ": must be [0, 0, 0] when boundary." + axis +
                         " = \"periodic\" (a wall velocity needs walls)");
    }
  }
  return derived;
}

}  // namespace immerse
