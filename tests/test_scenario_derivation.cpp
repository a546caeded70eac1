// A scenario kind derives only the keys the user left unset, records how each was derived, derives a group back from
// a key the user gave instead, and refuses a key that conflicts with a group the user gave too, naming both. Every
// kind and every key it derives.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "immerse/core/Error.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/simulation/Parameters.hpp"

using namespace immerse;

namespace {

const char* kShear = R"(
[scenario]
kind = "capsule_shear"
G = 0.05
[domain]
Lx = 5e-5
Ly = 5e-5
Lz = 5e-5
[boundary]
z = "wall"
[fluid]
rho = 1000.0
mu = 1e-3
[[membrane]]
radius = 5e-6
)";

const char* kCell = R"(
[scenario]
kind = "rbc_stretch"
[domain]
Lx = 3e-5
Ly = 3e-5
Lz = 3e-5
[boundary]
x = "wall"
y = "wall"
z = "wall"
[[membrane]]
R0 = 3.91e-6
)";

io::Config resolve(const std::string& text, std::vector<std::string> sets = {}) {
  return apply_scenario(run_schema().parse_string(text, "test", sets));
}

std::string with_kind(const char* base, const std::string& kind) {
  std::string t = base;
  const std::string from = "kind = \"capsule_shear\"";
  if (const auto at = t.find(from); at != std::string::npos) t.replace(at, from.size(), "kind = \"" + kind + "\"");
  return t;
}

std::string error_of(const std::string& text, const std::vector<std::string>& sets = {}) {
  try {
    resolve(text, sets);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// k = Re mu / (rho a^2) of the shear text above.
constexpr double kRate = 1e-3 * 1e-3 / (1000.0 * 5e-6 * 5e-6);

}  // namespace

class ShearKinds : public ::testing::TestWithParam<std::string> {};

TEST_P(ShearKinds, DeriveEveryUnsetKeyAndSayHow) {
  const io::Config c = resolve(with_kind(kShear, GetParam()));
  const double k = kRate, a = 5e-6, mu = 1e-3, Es = mu * k * a / 0.05;
  EXPECT_NEAR(c.get<double>("membrane[0].Es"), Es, 1e-12 * Es);
  EXPECT_EQ(c.get<double>("membrane[0].kappa_B"), 0.0);
  EXPECT_NEAR(c.get<double>("time.dt"), 0.01 / k, 1e-12 / k);
  EXPECT_NEAR(c.get<double>("time.end"), 10.0 / k, 1e-9 / k);
  EXPECT_EQ(c.get<std::string>("membrane[0].law"), "neo_hookean");
  EXPECT_EQ(c.get<std::string>("fluid.initial"), "couette");
  const Vec3 centre = c.get<Vec3>("membrane[0].center");
  EXPECT_DOUBLE_EQ(centre.x, 2.5e-5);
  EXPECT_DOUBLE_EQ(centre.z, 2.5e-5);
  EXPECT_NEAR(c.get<Vec3>("boundary.z_upper_velocity").x, 0.5 * k * 5e-5, 1e-12);
  EXPECT_NEAR(c.get<Vec3>("boundary.z_lower_velocity").x, -0.5 * k * 5e-5, 1e-12);
  std::vector<std::string> derived = {"membrane[0].Es",       "membrane[0].kappa_B",       "time.dt",
                                      "time.end",             "membrane[0].law",           "fluid.initial",
                                      "membrane[0].center",   "boundary.z_upper_velocity", "boundary.z_lower_velocity"};
  if (GetParam() == "oblate_shear")
    derived.insert(derived.end(), {"membrane[0].shape", "membrane[0].aspect_ratio", "membrane[0].inclination"});
  for (const auto& key : derived) {
    EXPECT_FALSE(c.given(key)) << key;
    EXPECT_NE(c.derivation(key).find("scenario.kind = \"" + GetParam() + "\""), std::string::npos) << key;
    EXPECT_NE(c.to_toml_string().find("# derived: " + c.derivation(key)), std::string::npos) << key;
  }
  EXPECT_NE(c.derivation("membrane[0].Es").find("scenario.G"), std::string::npos);
  EXPECT_TRUE(c.given("scenario.G"));
  EXPECT_EQ(c.derivation("scenario.G"), "");
}

TEST_P(ShearKinds, AKeyTheUserGaveStaysAndItsGroupFollowsFromIt) {
  const std::string text = with_kind(kShear, GetParam());
  // Without scenario.G in the file the modulus can be given instead: G follows from it.
  std::string no_g = text;
  no_g.erase(no_g.find("G = 0.05"), 8);
  const io::Config c = resolve(no_g, {"membrane[0].Es=2e-6", "time.dt=1e-3", "time.end=0.05", "membrane[0].kappa_B=1e-19"});
  EXPECT_EQ(c.get<double>("membrane[0].Es"), 2e-6);
  EXPECT_TRUE(c.given("membrane[0].Es"));
  EXPECT_NEAR(c.get<double>("scenario.G"), 1e-3 * kRate * 5e-6 / 2e-6, 1e-12);
  EXPECT_NE(c.derivation("scenario.G").find("from membrane[0].Es"), std::string::npos);
  EXPECT_EQ(c.get<double>("time.dt"), 1e-3);
  EXPECT_NEAR(c.get<double>("scenario.k_dt"), kRate * 1e-3, 1e-12);
  EXPECT_EQ(c.get<double>("time.end"), 0.05);
  EXPECT_NEAR(c.get<double>("scenario.kt_end"), kRate * 0.05, 1e-12);
  EXPECT_EQ(c.get<double>("membrane[0].kappa_B"), 1e-19);
  EXPECT_NEAR(c.get<double>("scenario.kappa_B_hat"), 1e-19 / (25e-12 * 2e-6), 1e-9);
  // Keys that only fill in a default keep the user's value: the law, the centre, the initial flow.
  const io::Config d = resolve(text, {"membrane[0].law=\"skalak\"", "membrane[0].center=[2e-5,2.5e-5,2.2e-5]",
                                      "fluid.initial=\"rest\""});
  EXPECT_EQ(d.get<std::string>("membrane[0].law"), "skalak");
  EXPECT_DOUBLE_EQ(d.get<Vec3>("membrane[0].center").x, 2e-5);
  EXPECT_EQ(d.get<std::string>("fluid.initial"), "rest");
  EXPECT_EQ(d.derivation("membrane[0].center"), "");
  // Both given and consistent: fine.
  EXPECT_NO_THROW(resolve(text, {"time.dt=" + std::to_string(0.01 / kRate)}));
}

TEST_P(ShearKinds, AKeyThatConflictsWithAGroupTheUserGaveIsAnErrorNamingBoth) {
  const std::string text = with_kind(kShear, GetParam());
  const std::string e = error_of(text, {"membrane[0].Es=1e-3"});
  EXPECT_NE(e.find("membrane[0].Es = 0.001 conflicts with scenario.G = 0.05"), std::string::npos) << e;
  EXPECT_NE(error_of(text, {"scenario.k_dt=0.02", "time.dt=1e-4"}).find("time.dt = 1e-04 conflicts with scenario.k_dt"),
            std::string::npos);
  EXPECT_NE(error_of(text, {"scenario.kt_end=2", "time.end=0.005"}).find("time.end = 0.005 conflicts with scenario.kt_end"),
            std::string::npos);
  EXPECT_NE(error_of(text, {"scenario.kappa_B_hat=0.01", "membrane[0].kappa_B=1e-10"})
                .find("membrane[0].kappa_B = 1e-10 conflicts with scenario.kappa_B_hat = 0.01"),
            std::string::npos);
  const std::string w = error_of(text, {"boundary.z_lower_velocity=[0,0,0]"});
  EXPECT_NE(w.find("boundary.z_lower_velocity = [0.0, 0.0, 0.0]: scenario.kind = \"" + GetParam() + "\" sets it to"),
            std::string::npos)
      << w;
  if (GetParam() == "oblate_shear") {
    EXPECT_NE(error_of(text, {"membrane[0].shape=\"sphere\""}).find("membrane[0].shape = \"sphere\""),
              std::string::npos);
    EXPECT_NE(error_of(text, {"scenario.aspect_ratio=0.5", "membrane[0].aspect_ratio=0.9"})
                  .find("membrane[0].aspect_ratio = 0.9 conflicts with scenario.aspect_ratio = 0.5"),
              std::string::npos);
    EXPECT_NE(error_of(text, {"scenario.theta0=0.5", "membrane[0].inclination=0.2"})
                  .find("membrane[0].inclination = 0.2 conflicts with scenario.theta0 = 0.5"),
              std::string::npos);
    const io::Config c = resolve(text, {"membrane[0].aspect_ratio=0.5"});
    EXPECT_EQ(c.get<double>("scenario.aspect_ratio"), 0.5);
  }
}

INSTANTIATE_TEST_SUITE_P(Scenario, ShearKinds, ::testing::Values("capsule_shear", "oblate_shear", "bending_shear"),
                         [](const auto& p) { return p.param; });

TEST(CellKinds, YeohConstantsFromMu0OrMu0FromC10) {
  const io::Config c = resolve(kCell);
  EXPECT_EQ(c.get<std::string>("membrane[0].shape"), "rbc");
  EXPECT_EQ(c.get<std::string>("membrane[0].law"), "yeoh");
  EXPECT_DOUBLE_EQ(c.get<double>("membrane[0].C10"), 7.3e-6 / 2);
  EXPECT_DOUBLE_EQ(c.get<double>("membrane[0].C30"), 7.3e-6 / 30);
  for (const char* key : {"membrane[0].shape", "membrane[0].law", "membrane[0].C10", "membrane[0].C30"})
    EXPECT_NE(c.derivation(key).find("scenario.kind = \"rbc_stretch\""), std::string::npos) << key;
  const io::Config d = resolve(kCell, {"membrane[0].C10=5e-6"});
  EXPECT_DOUBLE_EQ(d.get<double>("scenario.mu0"), 1e-5);
  EXPECT_DOUBLE_EQ(d.get<double>("membrane[0].C30"), 1e-5 / 30);
  const io::Config e = resolve(kCell, {"membrane[0].law=\"skalak\"", "membrane[0].C30=1e-7"});
  EXPECT_EQ(e.get<std::string>("membrane[0].law"), "skalak");
  EXPECT_EQ(e.get<double>("membrane[0].C30"), 1e-7);
  EXPECT_NE(error_of(kCell, {"scenario.mu0=1e-5", "membrane[0].C10=1e-6"})
                .find("membrane[0].C10 = 1e-06 conflicts with scenario.mu0 = 1e-05"),
            std::string::npos);
  EXPECT_NE(error_of(kCell, {"membrane[0].shape=\"sphere\""}).find("sets it to \"rbc\""), std::string::npos);
}

TEST(CellKinds, TheChannelCopiesTheCellToItsThirtyTwoPlaces) {
  std::string text = kCell;
  text.replace(text.find("kind = \"rbc_stretch\""), 20, "kind = \"rbc_channel\"");
  text.replace(text.find("y = \"wall\""), 10, "y = \"periodic\"");
  const io::Config c = resolve(text, {"domain.Lx=2.4e-5", "domain.Ly=4.8e-5", "domain.Lz=1.2e-5"});
  ASSERT_EQ(c.count("membrane"), 32u);
  const auto centres = channel_cell_centres(c);
  for (std::size_t i = 0; i < 32; ++i) {
    const std::string p = "membrane[" + std::to_string(i) + "].";
    EXPECT_DOUBLE_EQ(c.get<Vec3>(p + "center").y, centres[i].y) << i;
    EXPECT_EQ(c.get<double>(p + "C10"), c.get<double>("membrane[0].C10")) << i;
    EXPECT_NE(c.derivation(p + "center").find("rbc_channel"), std::string::npos) << i;
  }
  EXPECT_NE(error_of(text, {"membrane[0].center=[1e-6,1e-6,1e-6]"}).find("membrane[0].center = [1e-06, 1e-06, 1e-06]"),
            std::string::npos)
      << error_of(text, {"membrane[0].center=[1e-6,1e-6,1e-6]"});
}

// scenario.copies = [2, 2, 2] in a box twice as long along each axis: the 256-cell channel, each sub-box holding the
// 32 centres of the one-box channel shifted by its corner.
TEST(CellKinds, CopiesRepeatTheArrangementInSubBoxes) {
  std::string text = kCell;
  text.replace(text.find("kind = \"rbc_stretch\""), 20, "kind = \"rbc_channel\"");
  text.replace(text.find("y = \"wall\""), 10, "y = \"periodic\"");
  const io::Config one = resolve(text, {"domain.Lx=2.4e-5", "domain.Ly=4.8e-5", "domain.Lz=1.2e-5"});
  const io::Config c =
      resolve(text, {"domain.Lx=4.8e-5", "domain.Ly=9.6e-5", "domain.Lz=2.4e-5", "scenario.copies=[2, 2, 2]"});
  ASSERT_EQ(c.count("membrane"), 256u);
  const auto base = channel_cell_centres(one);
  for (int cz = 0; cz < 2; ++cz)
    for (int cy = 0; cy < 2; ++cy)
      for (int cx = 0; cx < 2; ++cx)
        for (std::size_t i = 0; i < 32; ++i) {
          const std::size_t k = 32 * (cx + 2 * (cy + 2 * cz)) + i;
          const Vec3 p = c.get<Vec3>("membrane[" + std::to_string(k) + "].center");
          EXPECT_NEAR(p.x, base[i].x + cx * 2.4e-5, 1e-18) << k;
          EXPECT_NEAR(p.y, base[i].y + cy * 4.8e-5, 1e-18) << k;
          EXPECT_NEAR(p.z, base[i].z + cz * 1.2e-5, 1e-18) << k;
        }
  EXPECT_NE(c.derivation("membrane[255].center").find("2 x 2 x 2 sub-boxes of scenario.copies"), std::string::npos);
  for (const char* bad : {"scenario.copies=[2, 2]", "scenario.copies=[1.5, 1, 1]"})
    EXPECT_NE(error_of(text, {bad}).find("scenario.copies = "), std::string::npos) << bad << ": " << error_of(text, {bad});
  EXPECT_NE(error_of(text, {"scenario.copies=[0, 1, 1]"}).find("scenario.copies"), std::string::npos);
}

TEST(CustomKind, AMembraneWithoutACentreSitsAtTheBoxCentre) {
  const char* text = R"(
[domain]
Lx = 4.0
Ly = 2.0
Lz = 6.0
origin = [1.0, 0.0, -3.0]
[[membrane]]
radius = 0.5
[[membrane]]
radius = 0.5
center = [2.0, 1.0, 1.0]
)";
  const io::Config c = resolve(text);
  const Vec3 p = c.get<Vec3>("membrane[0].center");
  EXPECT_EQ(p.x, 3.0);
  EXPECT_EQ(p.y, 1.0);
  EXPECT_EQ(p.z, 0.0);
  EXPECT_NE(c.derivation("membrane[0].center").find("the box centre"), std::string::npos);
  EXPECT_EQ(c.get<Vec3>("membrane[1].center").z, 1.0);
  EXPECT_TRUE(c.given("membrane[1].center"));
  EXPECT_EQ(c.derivation("membrane[1].center"), "");
  // A file mesh is placed where its file puts it (center is a displacement there).
  const io::Config g = resolve("[[membrane]]\nmesh.family = \"file\"\nmesh.file = \"cell.msh\"\n");
  EXPECT_EQ(g.get<Vec3>("membrane[0].center").x, 0.0);
  EXPECT_EQ(g.derivation("membrane[0].center"), "");
}

// Keys that do not apply to a membrane: refused by name when given, left out of the written configuration otherwise,
// which reads back as it was written.
TEST(MembraneKeys, KeysThatDoNotApplyAreRefusedWhenGivenAndLeftOutOtherwise) {
  const std::string file = "[[membrane]]\nmesh.family = \"file\"\nmesh.file = \"cell.msh\"\n";
  EXPECT_EQ(error_of(file, {"membrane[0].radius=1e-6"}),
            "membrane[0].radius: does not apply to mesh.family = \"file\" (the file gives the shape; use mesh.scale)");
  EXPECT_EQ(error_of(file, {"membrane[0].mesh.level=2"}),
            "membrane[0].mesh.level: does not apply to mesh.family = \"file\" (the file gives the nodes)");
  EXPECT_EQ(error_of(file, {"membrane[0].reference_radius=1e-6"}),
            "membrane[0].reference_radius: does not apply unless reference = \"sphere\"");
  EXPECT_EQ(error_of(file, {"membrane[0].mesh.reference_file=\"rest.msh\""}),
            "membrane[0].mesh.reference_file: does not apply unless reference = \"file\"");
  EXPECT_EQ(error_of("[[membrane]]\nradius = 1e-6\n", {"membrane[0].mesh.scale=1e-6"}),
            "membrane[0].mesh.scale: does not apply unless mesh.family = \"file\"");
  EXPECT_EQ(error_of("[[membrane]]\nreference = \"file\"\n"),
            "membrane[0].reference = \"file\": must be \"initial\" or \"sphere\" unless mesh.family = \"file\"");
  EXPECT_EQ(error_of(file, {"membrane[0].reference=\"sphere\"", "membrane[0].reference_radius=1e-6"}), "");

  const io::Config c = resolve(file);
  const std::string toml = c.to_toml_string();
  EXPECT_TRUE(c.left_out("membrane[0].radius"));
  EXPECT_FALSE(c.left_out("membrane[0].mesh.scale"));
  EXPECT_EQ(toml.find("\nradius = "), std::string::npos);
  EXPECT_EQ(toml.find("\nmesh.level = "), std::string::npos);
  EXPECT_NE(toml.find("# left out, as they do not apply to this entry: shape, radius, semi_axes, aspect_ratio, "
                      "inclination, R0, reference_radius, mesh.level, mesh.reference_file\n"),
            std::string::npos);
  // Resolved again, the same values; the derived ones (contact.range) are given now and lose their "# derived:" line.
  const auto without_derivations = [](const std::string& text) {
    std::istringstream in(text);
    std::string out;
    for (std::string line; std::getline(in, line);)
      if (line.rfind("# derived: ", 0) != 0) out += line + "\n";
    return out;
  };
  EXPECT_NE(toml.find("# derived: the grid spacing h"), std::string::npos);
  EXPECT_EQ(resolve(toml).to_toml_string(), without_derivations(toml));
  // A generated mesh: the file keys are left out.
  const std::string generated = resolve("[[membrane]]\nradius = 1e-6\n").to_toml_string();
  EXPECT_EQ(generated.find("\nmesh.file = "), std::string::npos);
  EXPECT_EQ(generated.find("\nmesh.scale = "), std::string::npos);
  EXPECT_NE(generated.find("\nradius = "), std::string::npos);
}

// In the shear scenarios the radius is the length a of the groups G and Re, also for a mesh read from a file.
TEST(MembraneKeys, TheShearScenariosTakeTheRadiusOfAFileMesh) {
  const std::string text = std::string(kShear) + "mesh.family = \"file\"\nmesh.file = \"cell.msh\"\n";
  EXPECT_EQ(error_of(text), "");
  EXPECT_FALSE(resolve(text).left_out("membrane[0].radius"));
  EXPECT_TRUE(resolve(text).left_out("membrane[0].shape"));
}

TEST(CustomKind, GivenAndDerivedDoNotChangeEquality) {
  const io::Config a = resolve(kShear);
  const io::Config b = run_schema().parse_string(a.to_toml_string(), "resolved");
  EXPECT_TRUE(a == b);
}

// "custom" is the default kind; "none", its former name, resolves to the same configuration (apart from the name).
TEST(CustomKind, NoneIsTheFormerNameOfCustom) {
  const char* text = R"(
[domain]
Lx = 4.0
Ly = 4.0
Lz = 4.0
[boundary]
z = "wall"
z_lower_velocity = [-1.0, 0.0, 0.0]
z_upper_velocity = [1.0, 0.0, 0.0]
[[membrane]]
radius = 0.5
)";
  const io::Config by_default = resolve(text);
  EXPECT_EQ(by_default.get<std::string>("scenario.kind"), "custom");
  const io::Config none = resolve(text, {"scenario.kind=\"none\""});
  EXPECT_TRUE(resolve(text, {"scenario.kind=\"custom\""}) == by_default);
  EXPECT_TRUE(resolve(text, {"scenario.kind=\"none\"", "scenario.kind=\"custom\""}) == by_default);
  EXPECT_EQ(none.value_text("membrane[0].center"), by_default.value_text("membrane[0].center"));
  // Walls z = const moving along x define the shear rate k = (u_upper - u_lower) / Lz of the kt column.
  EXPECT_DOUBLE_EQ(shear_rate(none), 0.5);
  EXPECT_DOUBLE_EQ(shear_rate(by_default), 0.5);
}
