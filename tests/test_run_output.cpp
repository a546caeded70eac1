// What a finished `immerse run` leaves in its --out folder: config.resolved.toml (re-parses to the configuration
// that ran), diagnostics.csv (the documented header, one row per step at t = step dt), the ParaView series
// (fields_*.h5 frames, membranes.xdmf, fluid.xdmf) and checkpoint.h5 (the last step).
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "PetscEnvironment.hpp"
#include "immerse/cli/RunCommand.hpp"
#include "immerse/io/Checkpoint.hpp"
#include "immerse/io/Hdf5.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/simulation/Parameters.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

constexpr int kSteps = 6, kFieldsEvery = 2;
constexpr double kDt = 0.125;

class RunOutputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    options_.file = scenario_file("oscillating_membrane_quick.toml");
    options_.sets = small_membrane_sets(kSteps);
    options_.sets.push_back("output.fields_every=" + std::to_string(kFieldsEvery));
    options_.out = dir_ / "out";
    std::ostringstream err;
    ASSERT_EQ(run_command(options_, log_, err), 0) << err.str();
    EXPECT_EQ(err.str(), "");
  }
  ScratchDir dir_{"output"};
  CommandLine options_;
  std::ostringstream log_;
};

TEST_F(RunOutputTest, ResolvedConfigurationReparsesToTheConfigurationThatRan) {
  const io::ConfigSchema schema = run_schema();
  const io::Config ran = apply_scenario(schema.parse_file(options_.file, options_.sets));
  const fs::path saved = options_.out / "config.resolved.toml";
  ASSERT_TRUE(fs::exists(saved));
  EXPECT_TRUE(schema.parse_file(saved, {}) == ran);
  // Standard output is short: the header names the version and the folders; the configuration is not echoed.
  EXPECT_EQ(log_.str().find(ran.to_toml_string()), std::string::npos) << log_.str();
  EXPECT_EQ(log_.str().rfind("# immerse " IMMERSE_VERSION " (commit ", 0), 0u) << log_.str();
  // The checkpoint carries it too.
  const auto ck = io::Checkpoint::read(options_.out / "checkpoint.h5");
  EXPECT_TRUE(schema.parse_string(ck.get_string("config"), "checkpoint") == ran);
  EXPECT_EQ(ck.get_int("step"), kSteps);
}

// --verbose prints the whole resolved configuration as well.
TEST(RunOutputVerbose, PrintsTheResolvedConfiguration) {
  ScratchDir dir("output");
  CommandLine o;
  o.file = scenario_file("oscillating_membrane_quick.toml");
  o.sets = small_membrane_sets(1);
  o.out = dir / "out";
  o.verbose = true;
  std::ostringstream log, err;
  ASSERT_EQ(run_command(o, log, err), 0) << err.str();
  const io::Config ran = apply_scenario(run_schema().parse_file(o.file, o.sets));
  EXPECT_NE(log.str().find(ran.to_toml_string()), std::string::npos) << log.str();
}

// The run folder says where it came from: version, commit, command line, start time, host and threads at the head
// of config.resolved.toml and as attributes of every HDF5 file; every diagnostics column with its unit.
TEST_F(RunOutputTest, FilesRecordTheirProvenanceAndUnits) {
  const std::string toml = read_text(options_.out / "config.resolved.toml");
  for (const char* key : {"immerse_version", "commit", "command_line", "start_time", "host", "threads"})
    EXPECT_NE(toml.find(std::string("# ") + key + ": "), std::string::npos) << key;
  EXPECT_NE(toml.find("# immerse_version: " IMMERSE_VERSION "\n"), std::string::npos);
  EXPECT_NE(toml.find("# command_line: immerse run " + options_.file.string() + "\n"), std::string::npos) << toml;
  for (const char* file : {"fields_000000.h5", "checkpoint.h5"}) {
    io::hdf5::Handle f = io::hdf5::open_file_readonly((options_.out / file).string());
    ASSERT_TRUE(f.valid()) << file;
    std::string value;
    for (const char* key : {"immerse_version", "commit", "command_line", "start_time", "host", "threads"}) {
      ASSERT_TRUE(io::hdf5::read_attribute(f.get(), key, value)) << file << ": " << key;
      EXPECT_FALSE(value.empty()) << file << ": " << key;
    }
    ASSERT_TRUE(io::hdf5::read_attribute(f.get(), "immerse_version", value));
    EXPECT_EQ(value, IMMERSE_VERSION);
  }
  const auto units = read_csv(options_.out / "diagnostics.columns.csv");
  const auto rows = read_csv(options_.out / "diagnostics.csv");
  ASSERT_EQ(units.size(), rows[0].size() + 1);
  EXPECT_EQ(units[0], (std::vector<std::string>{"column", "unit", "description"}));
  for (std::size_t c = 0; c < rows[0].size(); ++c) {
    ASSERT_EQ(units[c + 1].size(), 3u) << rows[0][c];
    EXPECT_EQ(units[c + 1][0], rows[0][c]);
  }
  EXPECT_EQ(units[2][1], "s");    // time
  EXPECT_EQ(units[9][1], "m^3");  // volume
  EXPECT_EQ(units[18][1], "1");   // D_ellipsoid
  EXPECT_EQ(units[20][1], "1");   // min_area_ratio
  EXPECT_EQ(units[21][1], "J");   // E_kinetic
  EXPECT_EQ(units[22][1], "W");   // dissipation
  EXPECT_EQ(units[29][1], "J");   // budget_residual
}

TEST_F(RunOutputTest, DiagnosticsHaveTheDocumentedHeaderAndOneRowPerStep) {
  const auto rows = read_csv(options_.out / "diagnostics.csv");
  // Header, the initial state (step 0), then one row per step.
  ASSERT_EQ(rows.size(), std::size_t(kSteps + 2));
  EXPECT_EQ(std::stol(rows[1][0]), 0);
  EXPECT_EQ(std::stod(rows[1][1]), 0.0);
  std::string header;
  for (const auto& c : rows[0]) header += (header.empty() ? "" : ",") + c;
  EXPECT_EQ(header,
            "step,time,dt,newton_its,gmres_its,fluid_solves,residual,wall_s,volume,area,cx,cy,cz,a1,a2,a3,D_xz,"
            "D_ellipsoid,theta,min_area_ratio,E_kinetic,dissipation,P_walls,P_body,E_elastic,E_bending,E_constraint,E_total,budget_residual");
  for (int s = 1; s <= kSteps; ++s) {
    const auto& r = rows[s + 1];
    ASSERT_EQ(r.size(), rows[0].size());
    EXPECT_EQ(std::stol(r[0]), s);
    EXPECT_NEAR(std::stod(r[1]), s * kDt, 1e-12);
    EXPECT_DOUBLE_EQ(std::stod(r[2]), kDt);
    EXPECT_GE(std::stol(r[3]), 1) << "jfnk: at least one Newton iteration a step";
    // The membrane stays near the centre of the box and keeps its volume 4/3 pi abc to the 66-node mesh's
    // accuracy; its longest semi-axis lies between the stress-free radius and the initial 0.25.
    EXPECT_NEAR(std::stod(r[10]), 0.5, 1e-3);
    EXPECT_NEAR(std::stod(r[8]), 4.0 / 3.0 * M_PI * 0.25 * 0.22 * 0.2, 0.1 * 4.0 / 3.0 * M_PI * 0.011);
    EXPECT_GT(std::stod(r[13]), 0.2);
    EXPECT_LT(std::stod(r[13]), 0.26);
  }
}

TEST_F(RunOutputTest, ParaViewSeriesHasOneFrameEveryFieldsEverySteps) {
  // Frames at steps 0, 2, 4, 6.
  const int frames = kSteps / kFieldsEvery + 1;
  for (int f = 0; f < frames; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "fields_%06d.h5", f);
    EXPECT_TRUE(fs::exists(options_.out / name)) << name;
  }
  EXPECT_FALSE(fs::exists(options_.out / "fields_000004.h5"));
  for (const char* xdmf : {"membranes.xdmf", "fluid.xdmf"}) {
    const std::string text = read_text(options_.out / xdmf);
    ASSERT_FALSE(text.empty()) << xdmf;
    for (int f = 0; f < frames; ++f) {
      char name[32];
      std::snprintf(name, sizeof name, "fields_%06d.h5", f);
      EXPECT_NE(text.find(name), std::string::npos) << xdmf << " does not reference " << name;
    }
  }
}

// The run ends with its profile by component, and the summary after it keeps full precision: D_xz printed as in
// diagnostics.csv to six significant digits (the profile's one-decimal format must not leak into it).
TEST_F(RunOutputTest, EndsWithTheProfileAndAFullPrecisionSummary) {
  const std::string log = log_.str();
  const auto profile = log.find("stepping took ");
  ASSERT_NE(profile, std::string::npos) << log;
  for (const char* part : {"membrane forces", "contact", "spreading", "fluid", "interpolation", "the rest"})
    EXPECT_NE(log.find(part, profile), std::string::npos) << part;
  const std::string key = "Taylor deformation D_xz = ";
  const auto at = log.find(key, profile);
  ASSERT_NE(at, std::string::npos) << log;
  const double printed = std::stod(log.substr(at + key.size()));
  const auto rows = read_csv(options_.out / "diagnostics.csv");
  const double saved = std::stod(rows.back()[16]);  // D_xz
  ASSERT_NE(saved, 0.0);
  EXPECT_NEAR(printed, saved, 1e-5 * std::abs(saved));
}

TEST(OutputWriter, WithoutFieldsNoParaViewFilesAndAPrefixPerMembrane) {
  // Two membranes side by side: the membrane columns are repeated with prefixes m0_, m1_.
  ScratchDir dir("output_two");
  const std::string base = read_text(scenario_file("oscillating_membrane_quick.toml"));
  const fs::path file = dir / "two.toml";
  std::ofstream(file) << base << "\n" << base.substr(base.find("[[membrane]]"));
  CommandLine o;
  o.file = file;
  o.sets = small_membrane_sets(2);
  for (const char* s : {"domain.Lx=2.0", "grid.nx=32", "membrane[0].center=[0.5,0.5,0.5]",
                        "membrane[1].center=[1.5,0.5,0.5]", "membrane[1].mesh.level=1"})
    o.sets.push_back(s);
  o.out = dir / "out";
  std::ostringstream log, err;
  ASSERT_EQ(run_command(o, log, err), 0) << err.str();
  const auto rows = read_csv(o.out / "diagnostics.csv");
  ASSERT_EQ(rows.size(), 4u);
  ASSERT_EQ(rows[0].size(), 8u + 2 * 12 + 4 + 2 * 3 + 2);
  EXPECT_EQ(rows[0][8], "m0_volume");
  EXPECT_EQ(rows[0][19], "m0_min_area_ratio");
  EXPECT_EQ(rows[0][20], "m1_volume");
  EXPECT_EQ(rows[0][30], "m1_theta");
  // Then the energy budget: the fluid's columns, each membrane's energies, the totals.
  EXPECT_EQ(rows[0][32], "E_kinetic");
  EXPECT_EQ(rows[0][36], "m0_E_elastic");
  EXPECT_EQ(rows[0][41], "m1_E_constraint");
  EXPECT_EQ(rows[0][42], "E_total");
  EXPECT_EQ(rows[0][43], "budget_residual");
  // E_total adds up the kinetic energy and the energies of both (stretched) capsules.
  const double E_total = std::stod(rows[3][42]);
  EXPECT_NEAR(E_total, std::stod(rows[3][32]) + std::stod(rows[3][36]) + std::stod(rows[3][39]), 1e-15 * E_total);
  EXPECT_GT(std::stod(rows[3][36]), 0);
  EXPECT_GT(std::stod(rows[3][39]), 0);
  // Mirror images about x = 1 in a symmetric box: same volumes, least area ratios and centroids at 0.5 and 1.5.
  EXPECT_NEAR(std::stod(rows[3][8]), std::stod(rows[3][20]), 1e-12);
  EXPECT_NEAR(std::stod(rows[3][19]), std::stod(rows[3][31]), 1e-9);
  EXPECT_NEAR(std::stod(rows[3][10]), 0.5, 1e-3);
  EXPECT_NEAR(std::stod(rows[3][22]), 1.5, 1e-3);
  EXPECT_FALSE(fs::exists(o.out / "membranes.xdmf"));
  EXPECT_FALSE(fs::exists(o.out / "fluid.xdmf"));
  EXPECT_FALSE(fs::exists(o.out / "fields_000000.h5"));
  EXPECT_TRUE(fs::exists(o.out / "checkpoint.h5"));
}

}  // namespace
