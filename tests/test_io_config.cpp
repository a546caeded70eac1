#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "immerse/core/Error.hpp"
#include "immerse/io/Config.hpp"
#include "immerse/io/ConfigSchema.hpp"

using namespace immerse;
using namespace immerse::io;

namespace {

ConfigSchema membrane_schema() {
  ConfigSchema m;
  m.add_string("shape", "sphere", {"sphere", "rbc", "gmsh"}, "initial shape");
  m.add_int("level", 2, Range::closed(0, 6), "icosahedral refinement level");
  m.add_string("law.name", "skalak", {"skalak", "neo_hookean"}, "membrane constitutive law");
  m.add_double("law.Es", 1.0, Range::positive(), "shear modulus (N/m)");
  m.add_double("law.C", 1.0, Range::non_negative(), "area-dilatation ratio Ea/Es (-)");
  m.add_vec3("position", {0, 0, 0}, Range::any(), "centre of the initial shape (m)");
  return m;
}

ConfigSchema schema() {
  ConfigSchema s;
  s.add_string("name", "run", {}, "run name");
  s.add_double("fluid.mu", 1e-3, Range::positive(), "dynamic viscosity (Pa s)");
  s.add_double("fluid.rho", 1000, Range::positive(), "density (kg/m^3)");
  s.add_int("grid.n", 32, Range::at_least(4), "cells along x");
  s.add_bool("grid.periodic_z", true, "periodic along z");
  s.add_string("time.scheme", "jfnk", {"jfnk", "quasi_newton", "euler", "rk2"}, "membrane time stepping");
  s.add_double("time.cfl", 0.5, Range::open_closed(0, 1), "CFL number (-)");
  s.add_double("scenario.G", 0.1, Range::at_least(0), "capillary number (-)");
  s.add_double_list("output.times", {0.5, 1.0}, Range::non_negative(), "output times (s)");
  s.add_table_array("membrane", membrane_schema(), 1, "one deformable membrane");
  return s;
}

const char* kGood = R"(name = "shear"
[fluid]
mu = 2          # an integer where a double is expected
[time]
scheme = "euler"
[[membrane]]
shape = "rbc"
law.Es = 5e-6
position = [1, 2.5, -3]
[[membrane]]
level = 4
[membrane.law]
C = 10.0
)";

// The message of the InputError `f` throws ("" if it throws none).
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string file_error(const std::string& toml, std::vector<std::string> sets = {}) {
  return error_of([&] { schema().parse_string(toml, "run.toml", sets); });
}

const char* kOneMembrane = "[[membrane]]\n";

}  // namespace

TEST(Config, DefaultsFilledAndFileValuesTyped) {
  const Config c = schema().parse_string(kGood, "run.toml");
  EXPECT_EQ(c.get<std::string>("name"), "shear");
  EXPECT_EQ(c.get<double>("fluid.mu"), 2.0);
  EXPECT_EQ(c.get<double>("fluid.rho"), 1000.0);  // default
  EXPECT_EQ(c.get<int>("grid.n"), 32);
  EXPECT_TRUE(c.get<bool>("grid.periodic_z"));
  EXPECT_EQ(c.get<std::string>("time.scheme"), "euler");
  EXPECT_EQ(c.get<std::vector<double>>("output.times"), (std::vector<double>{0.5, 1.0}));
  ASSERT_EQ(c.count("membrane"), 2u);
  EXPECT_EQ(c.get<std::string>("membrane[0].shape"), "rbc");
  EXPECT_EQ(c.get<double>("membrane[0].law.Es"), 5e-6);
  EXPECT_EQ(c.get<double>("membrane[0].law.C"), 1.0);  // entry default
  const Vec3 p = c.get<Vec3>("membrane[0].position");
  EXPECT_EQ(p.x, 1.0);
  EXPECT_EQ(p.y, 2.5);
  EXPECT_EQ(p.z, -3.0);
  EXPECT_EQ(c.entry("membrane", 1).get<std::int64_t>("level"), 4);
  EXPECT_EQ(c.entry("membrane", 1).get<double>("law.C"), 10.0);
  EXPECT_EQ(c.get<std::string>("membrane[1].shape"), "sphere");
  // Reading with a type other than declared is a programming error, not an input error.
  EXPECT_THROW(c.get<int>("fluid.mu"), std::logic_error);
  EXPECT_THROW(c.get<double>("fluid.nu"), std::logic_error);
}

TEST(Config, UnknownKeysNamedWithSuggestion) {
  EXPECT_EQ(file_error("[fluid]\nmuu = 1\n"), "config run.toml:2:1: unknown key fluid.muu (did you mean fluid.mu?)");
  EXPECT_EQ(file_error("[fluidd]\nmu = 1\n"), "config run.toml:2:1: unknown key fluidd.mu (did you mean fluid.mu?)");
  EXPECT_EQ(file_error("mu = 1\n"), "config run.toml:1:1: unknown key mu (did you mean fluid.mu?)");
  EXPECT_EQ(file_error("[time]\nmu = 1\n"), "config run.toml:2:1: unknown key time.mu (did you mean fluid.mu?)");
  EXPECT_EQ(file_error("completely_different = 1\n"), "config run.toml:1:1: unknown key completely_different");
  EXPECT_EQ(file_error("[[membrane]]\nlaw.Ess = 1\n"),
            "config run.toml:2:5: unknown key membrane[0].law.Ess (did you mean membrane[0].law.Es?)");
}

TEST(Config, WrongTypeOutOfRangeAndNonFiniteNamed) {
  EXPECT_EQ(file_error("[fluid]\nmu = \"abc\"\n"),
            "config run.toml:2:6: fluid.mu = \"abc\": must be a finite number > 0");
  EXPECT_EQ(file_error("[fluid]\nmu = -1\n"), "config run.toml:2:6: fluid.mu = -1: must be a finite number > 0");
  EXPECT_EQ(file_error("[fluid]\nmu = nan\n"), "config run.toml:2:6: fluid.mu = nan: must be a finite number > 0");
  EXPECT_EQ(file_error("[fluid]\nmu = inf\n"), "config run.toml:2:6: fluid.mu = inf: must be a finite number > 0");
  EXPECT_EQ(file_error("[time]\ncfl = 0.0\n"), "config run.toml:2:7: time.cfl = 0.0: must be a finite number in (0, 1]");
  EXPECT_EQ(file_error("[grid]\nn = 2.5\n"), "config run.toml:2:5: grid.n = 2.5: must be an integer >= 4");
  EXPECT_EQ(file_error("[grid]\nperiodic_z = 1\n"), "config run.toml:2:14: grid.periodic_z = 1: must be true or false");
  EXPECT_EQ(file_error("[time]\nscheme = \"rk4\"\n"),
            "config run.toml:2:10: time.scheme = \"rk4\": must be one of \"jfnk\", \"quasi_newton\", \"euler\", \"rk2\"");
  EXPECT_EQ(file_error("[output]\ntimes = [1, -2]\n"),
            "config run.toml:2:9: output.times = [ 1, -2 ]: must be a list of finite numbers, each >= 0");
  EXPECT_EQ(file_error("[fluid]\nmu = [1]\n"), "config run.toml:2:6: fluid.mu = [ 1 ]: must be a finite number > 0");
  EXPECT_EQ(file_error("[fluid.mu]\nx = 1\n"), "config run.toml:1:1: fluid.mu = a table: must be a finite number > 0");
  EXPECT_EQ(file_error("[[membrane]]\n[[membrane]]\nlaw.Es = -2\n"),
            "config run.toml:3:10: membrane[1].law.Es = -2: must be a finite number > 0");
  EXPECT_EQ(file_error("[[membrane]]\nposition = [1, 2]\n"),
            "config run.toml:2:12: membrane[0].position = [ 1, 2 ]: must be 3 finite numbers [x, y, z]");
  EXPECT_EQ(file_error("membrane = 3\n"), "config run.toml:1:12: membrane = 3: must be an array of tables [[membrane]]");
  EXPECT_EQ(file_error(""), "config run.toml: [[membrane]] given 0 times: must be at least 1");
}

TEST(Config, ParseErrorsAndUnreadableFilesAreOneLine) {
  // toml++'s description, prefixed with file:line:column.
  EXPECT_EQ(file_error("[fluid\nmu = 1\n"),
            "config run.toml:1:7: Error while parsing table header: expected ']', saw '\\n'");
  EXPECT_EQ(file_error("[fluid]\nmu = 1\nmu = 2\n"),
            "config run.toml:3:6: Error while parsing key-value pair: cannot redefine existing integer 'mu'");

  EXPECT_EQ(error_of([] { schema().parse_file("/nonexistent/run.toml"); }),
            "config /nonexistent/run.toml: cannot read: No such file or directory");
  EXPECT_EQ(error_of([] { schema().parse_file("/tmp"); }), "config /tmp: cannot read: Is a directory");
}

TEST(Config, OverridesUseTheDottedNames) {
  const Config c = schema().parse_string(
      kGood, "run.toml",
      std::vector<std::string>{"scenario.G=0.05", "time.scheme=\"jfnk\"", "fluid.rho = 3", "membrane[0].level=3",
                               "membrane[2].shape=gmsh", "membrane[2].law.C=0", "output.times=[0.25]",
                               "name=my run"});
  EXPECT_EQ(c.get<double>("scenario.G"), 0.05);
  EXPECT_EQ(c.get<std::string>("time.scheme"), "jfnk");
  EXPECT_EQ(c.get<double>("fluid.rho"), 3.0);
  EXPECT_EQ(c.get<int>("membrane[0].level"), 3);
  ASSERT_EQ(c.count("membrane"), 3u);  // membrane[2] appended
  EXPECT_EQ(c.get<std::string>("membrane[2].shape"), "gmsh");
  EXPECT_EQ(c.get<double>("membrane[2].law.C"), 0.0);
  EXPECT_EQ(c.get<std::vector<double>>("output.times"), std::vector<double>{0.25});
  EXPECT_EQ(c.get<std::string>("name"), "my run");

  const Config bare = schema().parse_string(kOneMembrane, "run.toml", std::vector<std::string>{"time.scheme=rk2"});
  EXPECT_EQ(bare.get<std::string>("time.scheme"), "rk2");

  // The overrides alone satisfy "at least one membrane".
  const Config only_sets = schema().parse_string("", "run.toml", std::vector<std::string>{"membrane[0].level=1"});
  EXPECT_EQ(only_sets.count("membrane"), 1u);
}

TEST(Config, BadOverridesNamed) {
  const auto set_error = [](std::string s) { return file_error(kOneMembrane, {std::move(s)}); };
  EXPECT_EQ(set_error("fluid.muu=1"), "--set: unknown key fluid.muu (did you mean fluid.mu?)");
  EXPECT_EQ(set_error("fluid.mu=-1"), "--set: fluid.mu = -1: must be a finite number > 0");
  EXPECT_EQ(set_error("fluid.mu=abc"), "--set: fluid.mu = abc: must be a finite number > 0");
  EXPECT_EQ(set_error("fluid.mu=nan"), "--set: fluid.mu = nan: must be a finite number > 0");
  EXPECT_EQ(set_error("time.scheme=rk4"),
            "--set: time.scheme = \"rk4\": must be one of \"jfnk\", \"quasi_newton\", \"euler\", \"rk2\"");
  EXPECT_EQ(set_error("grid.n=8.5"), "--set: grid.n = 8.5: must be an integer >= 4");
  EXPECT_EQ(set_error("fluid.mu"), "--set fluid.mu: must be KEY=VALUE");
  EXPECT_EQ(set_error("membrane[3].level=1"), "--set: membrane[3].level: index 3 given: must be in [0, 1] (1 adds an entry)");
  EXPECT_EQ(set_error("membrane[0].lvl=1"), "--set: unknown key membrane[0].lvl (did you mean membrane[0].level?)");
  EXPECT_EQ(set_error("membrane[0].law.Es=0"), "--set: membrane[0].law.Es = 0: must be a finite number > 0");
}

TEST(Config, ResolvedTomlRoundTripsExactly) {
  const Config c = schema().parse_string(
      kGood, "run.toml",
      std::vector<std::string>{"name=\"quote \\\" and \\\\ back\"", "scenario.G=0.1", "fluid.rho=1e-300",
                               "membrane[1].position=[-0.0, 0.30000000000000004, 1e22]"});
  const std::string text = c.to_toml_string();
  const ConfigSchema kSchema = schema();
  const Config again = schema().parse_string(text, "config.resolved.toml");
  EXPECT_TRUE(again == c) << text;
  EXPECT_EQ(again.get<std::string>("name"), "quote \" and \\ back");
  EXPECT_EQ(again.get<Vec3>("membrane[1].position").y, 0.30000000000000004);
  EXPECT_TRUE(std::signbit(again.get<Vec3>("membrane[1].position").x));
  // Doc strings become comments; every key appears.
  EXPECT_NE(text.find("# dynamic viscosity (Pa s); a finite number > 0; default 0.001\nmu = 2.0\n"), std::string::npos)
      << text;
  for (const auto& k : kSchema.keys()) EXPECT_NE(text.find(k.doc), std::string::npos) << k.key;

  // A different configuration compares unequal.
  const Config other = schema().parse_string(text, "x.toml", std::vector<std::string>{"membrane[1].law.C=2"});
  EXPECT_FALSE(other == c);

  const auto path = std::filesystem::temp_directory_path() / "immerse_test_config.resolved.toml";
  c.save(path);
  EXPECT_TRUE(schema().parse_file(path) == c);
  std::filesystem::remove(path);
}

TEST(Config, HelpListsEveryKeyWithDefaultAndRange) {
  std::ostringstream os;
  schema().print_help(os);
  const std::string h = os.str();
  const ConfigSchema kSchema = schema();
  EXPECT_NE(h.find("  fluid.mu = 0.001\n      dynamic viscosity (Pa s); a finite number > 0\n"), std::string::npos) << h;
  EXPECT_NE(h.find("  membrane[i].law.Es = 1.0\n      shear modulus (N/m); a finite number > 0\n"), std::string::npos);
  EXPECT_NE(h.find("[[membrane]]"), std::string::npos);
  for (const auto& k : kSchema.keys()) EXPECT_NE(h.find(k.key), std::string::npos);
}

TEST(Config, SchemaRejectsInconsistentDeclarations) {
  ConfigSchema s;
  s.add_double("fluid.mu", 1, Range::positive(), "viscosity");
  EXPECT_THROW(s.add_double("fluid.mu", 1, Range::positive(), "again"), std::logic_error);
  EXPECT_THROW(s.add_double("fluid", 1, Range::positive(), "prefix of a key"), std::logic_error);
  EXPECT_THROW(s.add_double("fluid.mu.x", 1, Range::positive(), "below a key"), std::logic_error);
  EXPECT_THROW(s.add_double("fluid.nu", -1, Range::positive(), "default out of range"), std::logic_error);
  EXPECT_THROW(s.add_string("scheme", "rk4", {"euler"}, "default not allowed"), std::logic_error);
  EXPECT_THROW(s.add_int("bad key", 1, Range::any(), "space in name"), std::logic_error);
  EXPECT_TRUE(Range::closed(0, 1).contains(1));
  EXPECT_FALSE(Range::closed_open(0, 1).contains(1));
  EXPECT_EQ(Range::closed_open(0, 1).describe(), "in [0, 1)");
  EXPECT_EQ(Range::at_most(2.5).describe(), "<= 2.5");
  EXPECT_EQ(Range::less_than(-1).describe(), "< -1");
}
