#include "immerse/scenario/Scenario.hpp"

#include "immerse/simulation/Parameters.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <utility>
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
std::string brief(double v) {  // for messages
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}
bool is_shear(const std::string& kind) { return is_shear_kind(kind); }
}  // namespace

double shear_rate(const io::Config& c) {
  if (is_shear(c.get<std::string>("scenario.kind"))) {
    const double a = c.get<double>("membrane[0].radius");
    return c.get<double>("scenario.Re") * c.get<double>("fluid.mu") / (c.get<double>("fluid.rho") * a * a);
  }
  // Any other kind: walls z = const moving along x only, as in a plane Couette flow.
  if (c.get<std::string>("boundary.z") != "wall") return 0.0;
  const Vec3 lo = c.get<Vec3>("boundary.z_lower_velocity"), hi = c.get<Vec3>("boundary.z_upper_velocity");
  if (lo.y != 0 || lo.z != 0 || hi.y != 0 || hi.z != 0) return 0.0;
  return std::abs(hi.x - lo.x) / c.get<double>("domain.Lz");
}

std::array<int, 3> channel_copies(const io::Config& c) {
  const auto v = c.get<std::vector<double>>("scenario.copies");
  std::array<int, 3> n{};
  const bool whole = v.size() == 3 && std::ranges::all_of(v, [](double x) { return x >= 1 && x <= 1e4 && x == std::floor(x); });
  if (!whole)
    throw InputError("scenario.copies = " + c.value_text("scenario.copies") +
                     ": must be three whole numbers >= 1 (copies along x, y and z), e.g. [2, 2, 2]");
  for (int a = 0; a < 3; ++a) n[a] = static_cast<int>(v[a]);
  return n;
}

std::vector<Vec3> channel_cell_centres(const io::Config& c) {
  const Vec3 o = c.get<Vec3>("domain.origin");
  const auto n = channel_copies(c);
  const double Lx = c.get<double>("domain.Lx") / n[0], Ly = c.get<double>("domain.Ly") / n[1],
               Lz = c.get<double>("domain.Lz") / n[2];
  std::vector<Vec3> box;  // the 32 centres in one sub-box
  for (int k = 0; k < 5; ++k)
    for (double x : {0.25, 0.75}) box.push_back({x * Lx, (k + 0.25) * Ly / 5, 0.18 * Lz});
  for (int k = 0; k < 4; ++k) {
    for (double x : {0.2, 0.8}) box.push_back({x * Lx, (k + 0.125) * Ly / 4, 0.5 * Lz});
    box.push_back({0.5 * Lx, (k + 0.625) * Ly / 4, 0.5 * Lz});
  }
  for (int k = 0; k < 5; ++k)
    for (double x : {0.25, 0.75}) box.push_back({x * Lx, (k + 0.75) * Ly / 5, 0.82 * Lz});
  std::vector<Vec3> centres;
  for (int cz = 0; cz < n[2]; ++cz)
    for (int cy = 0; cy < n[1]; ++cy)
      for (int cx = 0; cx < n[0]; ++cx)
        for (const Vec3& p : box) centres.push_back(o + p + Vec3{cx * Lx, cy * Ly, cz * Lz});
  return centres;
}

namespace {

/// The numbers in a value's TOML text ("4e-06", "[1.0, 2.0, 3.0]"), and the rest of the text.
std::pair<std::vector<double>, std::string> split_numbers(const std::string& text) {
  std::vector<double> numbers;
  std::string rest;
  for (std::size_t i = 0; i < text.size();) {
    char* end = nullptr;
    const double v = std::strtod(text.c_str() + i, &end);
    const bool number = end != text.c_str() + i && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '-' ||
                                                   text[i] == '+' || text[i] == '.');
    if (number) {
      numbers.push_back(v);
      i = static_cast<std::size_t>(end - text.c_str());
    } else {
      rest += text[i++];
    }
  }
  return {numbers, rest};
}

/// Equal values up to the round-off of deriving one from the other (relative 1e-9).
bool same_value(const std::string& a, const std::string& b) {
  const auto [x, xr] = split_numbers(a);
  const auto [y, yr] = split_numbers(b);
  if (xr != yr || x.size() != y.size()) return false;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (std::abs(x[i] - y[i]) > 1e-9 * std::max(std::abs(x[i]), std::abs(y[i]))) return false;
  return true;
}

/// Writes a scenario kind's derived values into the keys the user left unset; a key the user gave keeps its value.
/// Where a derived key and the group it comes from are both given and disagree, that is an error naming both.
class Derivation {
 public:
  Derivation(const io::Config& config, const std::string& kind) : c_(config), kind_("scenario.kind = \"" + kind + "\"") {}

  /// `key` = text (`what` it is) unless the user gave it (then the user's value stays).
  void fill(const std::string& key, const std::string& text, const std::string& what) {
    if (!c_.given(key)) c_.derive(key, text, kind_ + ": " + what);
  }

  /// `key` = text (`what` it is); a value the user gave must be that one.
  void fix(const std::string& key, const std::string& text, const std::string& what, const std::string& instead) {
    if (c_.given(key) && !same_value(c_.value_text(key), text))
      throw InputError(key + " = " + c_.value_text(key) + ": " + kind_ + " sets it to " + text + " (" + what +
                       "); leave it unset" + instead);
    c_.derive(key, text, kind_ + ": " + what);
  }

  /// A key and the nondimensional group it follows from: key = forward(group). The user may give either; the other
  /// is derived (the group back from the key by `inverse`); both given must agree.
  template <class Forward, class Inverse>
  void pair(const std::string& key, const std::string& group, const std::string& other_sources, Forward forward,
            Inverse inverse) {
    const bool key_given = c_.given(key), group_given = c_.given(group);
    const double derived = forward(c_.get<double>(group));
    if (key_given && group_given) {
      if (!same_value(c_.value_text(key), num(derived)))
        throw InputError(key + " = " + c_.value_text(key) + " conflicts with " + group + " = " +
                         c_.value_text(group) + " (" + kind_ + " derives " + key + " = " + brief(derived) + " from it" +
                         (other_sources.empty() ? "" : " and " + other_sources) + "): give only one of them");
    } else if (key_given) {
      c_.derive(group, num(inverse(c_.get<double>(key))),
                kind_ + " from " + key + (other_sources.empty() ? "" : ", " + other_sources));
    } else {
      c_.derive(key, num(derived), kind_ + " from " + group + (other_sources.empty() ? "" : ", " + other_sources));
    }
  }

  const io::Config& config() const { return c_; }
  io::Config take() { return std::move(c_); }

 private:
  io::Config c_;
  std::string kind_;
};

std::string vec(const Vec3& p) {
  std::ostringstream s;  // a stream: GCC 12 warns (-Wrestrict) on this as a chain of string concatenations
  s << '[' << num(p.x) << ", " << num(p.y) << ", " << num(p.z) << ']';
  return s.str();
}

Vec3 box_centre(const io::Config& c) {
  const Vec3 o = c.get<Vec3>("domain.origin");
  return {o.x + 0.5 * c.get<double>("domain.Lx"), o.y + 0.5 * c.get<double>("domain.Ly"),
          o.z + 0.5 * c.get<double>("domain.Lz")};
}

// Shear scenarios (see the header): E_s, kappa_B, time.dt and time.end from G, kappa_B_hat, k_dt and kt_end (or the
// groups back from the keys the user gave), the walls moving with -+ k Lz / 2, the capsule at the box centre.
io::Config derive_shear(const io::Config& config, const std::string& kind) {
  if (config.count("membrane") != 1) throw InputError("scenario.kind = \"" + kind + "\": needs exactly one [[membrane]]");
  require(config.get<std::string>("boundary.z") == "wall", "boundary.z", "\"wall\" for scenario.kind = \"" + kind + "\"");
  Derivation d(config, kind);
  const double a = config.get<double>("membrane[0].radius"), mu = config.get<double>("fluid.mu");
  const double k = shear_rate(config), Lz = config.get<double>("domain.Lz");
  const std::string rate = "scenario.Re, fluid.mu, fluid.rho, membrane[0].radius";
  const std::string own = "; for other walls use scenario.kind = \"custom\"";
  d.fill("membrane[0].law", "\"neo_hookean\"", "the neo-Hookean capsule of §4.2");
  d.pair("membrane[0].Es", "scenario.G", rate, [&](double G) { return mu * k * a / G; },
         [&](double Es) { return mu * k * a / Es; });
  const double Es = d.config().get<double>("membrane[0].Es");
  d.pair("membrane[0].kappa_B", "scenario.kappa_B_hat", "membrane[0].Es, membrane[0].radius",
         [&](double hat) { return hat * a * a * Es; }, [&](double kB) { return kB / (a * a * Es); });
  d.fill("membrane[0].center", vec(box_centre(config)), "the box centre");
  const std::string flow = "the shear flow u = (k (z - z_c), 0, 0), k from " + rate;
  d.fix("boundary.z_lower_velocity", vec({-0.5 * k * Lz, 0, 0}), flow, own);
  d.fix("boundary.z_upper_velocity", vec({0.5 * k * Lz, 0, 0}), flow, own);
  d.fill("fluid.initial", "\"couette\"", "the undisturbed shear flow");
  d.pair("time.dt", "scenario.k_dt", rate, [&](double kdt) { return kdt / k; }, [&](double dt) { return k * dt; });
  d.pair("time.end", "scenario.kt_end", rate, [&](double kt) { return kt / k; }, [&](double t) { return k * t; });
  if (kind == "oblate_shear") {
    d.fix("membrane[0].shape", "\"oblate\"", "the oblate capsule of §4.2.2", "");
    const auto same = [](double x) { return x; };
    d.pair("membrane[0].aspect_ratio", "scenario.aspect_ratio", "", same, same);
    d.pair("membrane[0].inclination", "scenario.theta0", "", same, same);
  }
  return d.take();
}

// rbc_stretch, rbc_channel: the biconcave cell with the Yeoh law, C10 = mu0/2, C30 = mu0/30; the channel copies the
// cell to the 32 positions of channel_cell_centres in each of the scenario.copies sub-boxes.
io::Config derive_cells(const io::Config& config, const std::string& kind) {
  if (config.count("membrane") != 1)
    throw InputError("scenario.kind = \"" + kind + "\": needs exactly one [[membrane]] (" +
                     (kind == "rbc_channel" ? "the template of every cell" : "the cell") + "), given " +
                     std::to_string(config.count("membrane")));
  Derivation d(config, kind);
  d.fix("membrane[0].shape", "\"rbc\"", "the biconcave cell of eq. (45)", "");
  d.fill("membrane[0].law", "\"yeoh\"", "the Yeoh law of §4.3");
  d.pair("membrane[0].C10", "scenario.mu0", "", [](double mu0) { return mu0 / 2; }, [](double C10) { return 2 * C10; });
  const double mu0 = d.config().get<double>("scenario.mu0");
  d.fill("membrane[0].C30", num(mu0 / 30), "C30 = mu0 / 30 from scenario.mu0");
  if (kind == "rbc_stretch") return d.take();
  for (const auto& [axis, bc] : {std::pair{"x", "wall"}, {"y", "periodic"}, {"z", "wall"}})
    require(config.get<std::string>(std::string("boundary.") + axis) == bc, std::string("boundary.") + axis,
            std::string("\"") + bc + "\" for scenario.kind = \"rbc_channel\" (flow along the periodic y axis)");
  const auto centres = channel_cell_centres(config);
  const auto copies = channel_copies(config);
  const std::string arrangement =
      copies == std::array<int, 3>{1, 1, 1}
          ? std::string("the channel's arrangement of 32 cells in the domain")
          : "the channel's arrangement of 32 cells in each of the " + std::to_string(copies[0]) + " x " +
                std::to_string(copies[1]) + " x " + std::to_string(copies[2]) + " sub-boxes of scenario.copies";
  d.fix("membrane[0].center", vec(centres[0]), arrangement, "; for other positions use scenario.kind = \"custom\"");
  io::Config derived = d.take();
  const io::Config cell = derived.entry("membrane", 0);
  const std::string how = "scenario.kind = \"rbc_channel\" from membrane[0] and " + arrangement;
  for (std::size_t i = 1; i < centres.size(); ++i) {
    const std::string prefix = "membrane[" + std::to_string(i) + "].";
    for (const auto& key : cell.schema().keys())
      if (key.key != "center") derived.derive(prefix + key.key, cell.value_text(key.key), how);
    derived.derive(prefix + "center", vec(centres[i]), how);
  }
  return derived;
}

// Any kind: a generated membrane whose centre is not given sits at the box centre.
io::Config derive_centres(io::Config config) {
  for (std::size_t i = 0; i < config.count("membrane"); ++i) {
    const std::string p = "membrane[" + std::to_string(i) + "].";
    if (!config.given(p + "center") && config.derivation(p + "center").empty() &&
        config.get<std::string>(p + "mesh.family") != "file")
      config.derive(p + "center", vec(box_centre(config)), "the box centre (" + p + "center not given)");
  }
  return config;
}

// Why a key of a [[membrane]] entry does not apply to it, or "" if it does. In the shear scenarios the radius is the
// length a of the groups G and Re, also for a mesh read from a file.
// The keys the user gave to a membrane they do not apply to.
void check_membrane_keys(const io::Config& config) {
  const bool shear = is_shear(config.get<std::string>("scenario.kind"));
  for (std::size_t i = 0; i < config.count("membrane"); ++i) {
    const io::Config& m = config.entry("membrane", i);
    const std::string p = "membrane[" + std::to_string(i) + "].";
    for (const auto& key : m.schema().keys())
      if (m.given(key.key))
        if (const std::string why = membrane_key_not_applying(m, key.key, shear); !why.empty())
          throw InputError(p + key.key + ": " + why);
    if (m.get<std::string>("reference") == "file" && m.get<std::string>("mesh.family") != "file")
      throw InputError(p + "reference = \"file\": must be \"initial\" or \"sphere\" unless mesh.family = "
                       "\"file\"");
  }
}

// The keys the user gave to a wall they do not apply to (radius with shape = "surface", file with a tube, ...).
// The wall a scenario kind measures, before the keys of the entries (a key of another shape is then the lesser error).
void check_kind_walls(const io::Config& config) {
  const std::string kind = config.get<std::string>("scenario.kind");
  const auto first_is = [&](const std::string& shape) {
    return config.count("wall") > 0 && config.entry("wall", 0).get<std::string>("shape") == shape;
  };
  if (kind == "tube_flow")
    require(first_is("tube"), "wall[0].shape",
            "\"tube\" for scenario.kind = \"tube_flow\" (the tube whose flow rate it reports)");
  if (kind == "capsule_constriction")
    require(first_is("constriction"), "wall[0].shape",
            "\"constriction\" for scenario.kind = \"capsule_constriction\" (the constriction it measures)");
}

void check_wall_keys(const io::Config& config) {
  for (std::size_t i = 0; i < config.count("wall"); ++i) {
    const io::Config& w = config.entry("wall", i);
    const std::string p = "wall[" + std::to_string(i) + "].";
    for (const auto& key : w.schema().keys())
      if (w.given(key.key))
        if (const std::string why = wall_key_not_applying(w, key.key); !why.empty())
          throw InputError(p + key.key + ": " + why);
    if (w.get<std::string>("shape") == "surface" && w.get<std::string>("file").empty())
      throw InputError(p + "file: must be given (an STL or Gmsh file name) when shape = \"surface\"");
  }
}

// Any kind: contact within one grid spacing unless contact.range is given.
io::Config derive_contact(io::Config config) {
  if (!config.given("contact.range"))
    config.derive("contact.range", num(config.get<double>("domain.Lx") / config.get<int>("grid.nx")),
                  "the grid spacing h = domain.Lx / grid.nx (contact.range not given)");
  return config;
}

// suspension_shear: a plane Couette flow along x between walls z = const, whatever fills it.
io::Config check_suspension_shear(const io::Config& config) {
  const std::string kind = "\"wall\" for scenario.kind = \"suspension_shear\" (plane Couette flow along x)";
  require(config.get<std::string>("boundary.z") == "wall", "boundary.z", kind);
  require(config.get<std::string>("boundary.x") == "periodic", "boundary.x",
          "\"periodic\" for scenario.kind = \"suspension_shear\" (the flow direction)");
  if (shear_rate(config) == 0)
    throw InputError("boundary.z_upper_velocity = " + config.value_text("boundary.z_upper_velocity") +
                     ": scenario.kind = \"suspension_shear\" needs the walls z = const moving along x only, at "
                     "different velocities (boundary.z_lower_velocity = " +
                     config.value_text("boundary.z_lower_velocity") + ")");
  return config;
}

io::Config derive(const io::Config& config) {
  const std::string kind = config.get<std::string>("scenario.kind");
  if (kind == "suspension_shear") return derive_contact(derive_centres(check_suspension_shear(config)));
  if (kind == "capsule_constriction") {
    // (an axis that is not a coordinate axis is the wall's error, named by WallGeometry)
    const Vec3 axis = config.entry("wall", 0).get<Vec3>("axis"), Q = config.get<Vec3>("fluid.flow_rate");
    const int along = (axis.x != 0) + (axis.y != 0) + (axis.z != 0);
    for (int a = 0; a < 3 && along == 1; ++a)
      if ((axis[a] == 0) != (Q[a] == 0))
        throw InputError("fluid.flow_rate = " + config.value_text("fluid.flow_rate") +
                         ": scenario.kind = \"capsule_constriction\" holds a flow rate along the constriction's axis "
                         "wall[0].axis = " + config.entry("wall", 0).value_text("axis"));
  }
  if (kind == "rbc_stretch" || kind == "rbc_channel") return derive_contact(derive_centres(derive_cells(config, kind)));
  if (is_shear(kind)) return derive_contact(derive_centres(derive_shear(config, kind)));
  return derive_contact(derive_centres(config));
}

}  // namespace

io::Config apply_scenario(const io::Config& config) {
  check_membrane_keys(config);
  check_kind_walls(config);
  check_wall_keys(config);
  io::Config derived = derive(config);
  leave_out_inapplicable(derived);
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
