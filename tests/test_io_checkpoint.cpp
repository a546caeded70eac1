#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "immerse/core/Error.hpp"
#include "immerse/io/Checkpoint.hpp"
#include "immerse/io/Hdf5.hpp"

using namespace immerse;
using namespace immerse::io;
namespace fs = std::filesystem;

namespace {

// HDF5 1.10 keeps a few free-list blocks after it fails to load a damaged object header; at exit its library
// shutdown then prints "HDF5: infinite loop closing library". The sweep below provokes exactly that, so this
// test program skips HDF5's atexit shutdown (the process is ending anyway). Must run before any HDF5 call.
const bool kNoHdf5Atexit = H5dont_atexit() >= 0;

// Removes this program's temporary directory at the end.
class ScratchCleanup : public ::testing::Environment {
 public:
  void TearDown() override {
    fs::remove_all(fs::temp_directory_path() / ("immerse_test_checkpoint_" + std::to_string(::getpid())));
  }
};
const auto* const kCleanup = ::testing::AddGlobalTestEnvironment(new ScratchCleanup);

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("immerse_test_checkpoint_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

// A marker value whose bytes are easy to find in the file.
constexpr double kMarker = 1.2345678901234567e-300;

Checkpoint sample() {
  Checkpoint c;
  std::vector<double> u(2 * 3 * 4);
  for (std::size_t i = 0; i < u.size(); ++i) u[i] = std::sin(0.37 * static_cast<double>(i)) / 3.0;
  u[7] = kMarker;
  u[8] = -0.0;
  u[9] = std::numeric_limits<double>::denorm_min();
  c.put_array("velocity_x", u, {2, 3, 4});
  c.put_array("empty", {});
  c.put_int("step", 123456789012345);
  c.put_int("negative", -7);
  c.put_double("time", 0.1 + 0.2);
  c.put_double("nan_is_kept", std::numeric_limits<double>::quiet_NaN());
  c.put_string("config", "[fluid]\nmu = 0.001  # \"quoted\"\n");
  c.put_string("empty_string", "");
  return c;
}

std::vector<char> slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void dump(const fs::path& p, const std::vector<char>& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Checkpoint, RoundTripIsBitwise) {
  const fs::path p = scratch("ck.h5");
  const Checkpoint c = sample();
  c.write(p);
  const Checkpoint r = Checkpoint::read(p);
  EXPECT_TRUE(r == c);
  EXPECT_EQ(r.checksum(), c.checksum());
  EXPECT_EQ(r.shape("velocity_x"), (std::vector<std::size_t>{2, 3, 4}));
  EXPECT_EQ(r.array("velocity_x")[7], kMarker);
  EXPECT_TRUE(std::signbit(r.array("velocity_x")[8]));
  EXPECT_EQ(r.array("velocity_x")[9], std::numeric_limits<double>::denorm_min());
  EXPECT_TRUE(r.array("empty").empty());
  EXPECT_EQ(r.shape("empty"), std::vector<std::size_t>{0});
  EXPECT_EQ(r.get_int("step"), 123456789012345);
  EXPECT_EQ(r.get_int("negative"), -7);
  EXPECT_EQ(r.get_double("time"), 0.1 + 0.2);
  EXPECT_TRUE(std::isnan(r.get_double("nan_is_kept")));
  EXPECT_EQ(r.get_string("config"), "[fluid]\nmu = 0.001  # \"quoted\"\n");
  EXPECT_EQ(r.get_string("empty_string"), "");
  EXPECT_EQ(error_of([&] { r.get_int("time"); }), "checkpoint " + p.string() + ": no integer named time");
  // No temporary is left behind.
  for (const auto& e : fs::directory_iterator(p.parent_path()))
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();

  // A checkpoint differing in one bit of one value compares unequal and has another checksum.
  Checkpoint d;
  auto u = c.array("velocity_x");
  u[3] = std::nextafter(u[3], 1.0);
  d.put_array("velocity_x", u, {2, 3, 4});
  Checkpoint e;
  e.put_array("velocity_x", c.array("velocity_x"), {2, 3, 4});
  EXPECT_NE(d.checksum(), e.checksum());
  EXPECT_FALSE(d == e);
}

TEST(Checkpoint, FlippedByteInDataIsRefused) {
  const fs::path p = scratch("flip.h5");
  sample().write(p);
  auto bytes = slurp(p);
  const auto* m = reinterpret_cast<const char*>(&kMarker);
  const auto at = std::search(bytes.begin(), bytes.end(), m, m + sizeof(double));
  ASSERT_NE(at, bytes.end());
  *(at + 3) ^= 0x10;
  dump(p, bytes);
  EXPECT_EQ(error_of([&] { Checkpoint::read(p); }), "checkpoint " + p.string() + " is corrupted: checksum mismatch");
}

TEST(Checkpoint, AnyFlippedByteIsRefusedOrHarmless) {
  // Flip bytes all over the file (metadata included): reading either refuses with an InputError or returns
  // exactly the original content (the byte was unused padding); it never returns altered data or crashes.
  const fs::path p = scratch("sweep.h5");
  const Checkpoint c = sample();
  c.write(p);
  const auto original = slurp(p);
  int refused = 0, harmless = 0;
  for (std::size_t i = 0; i < original.size(); i += 13) {
    auto bytes = original;
    bytes[i] = static_cast<char>(bytes[i] ^ 0x5a);
    dump(p, bytes);
    try {
      EXPECT_TRUE(Checkpoint::read(p) == c) << "byte " << i;
      ++harmless;
    } catch (const InputError& e) {
      const std::string m = e.what();
      const std::string who = "checkpoint " + p.string();
      EXPECT_TRUE(m.starts_with(who + " is corrupted: ") || m == who + " is truncated or not an HDF5 file") << m;
      ++refused;
    }
  }
  std::cout << "file " << original.size() << " bytes: " << refused << " flips refused, " << harmless
            << " harmless\n";
  EXPECT_GT(refused, 0);
  EXPECT_TRUE(kNoHdf5Atexit);
}

TEST(Checkpoint, TruncatedForeignAndMissingFilesAreRefused) {
  const fs::path p = scratch("trunc.h5");
  sample().write(p);
  auto bytes = slurp(p);
  bytes.resize(bytes.size() / 2);
  dump(p, bytes);
  EXPECT_EQ(error_of([&] { Checkpoint::read(p); }), "checkpoint " + p.string() + " is truncated or not an HDF5 file");

  const fs::path text = scratch("text.h5");
  dump(text, {'h', 'e', 'l', 'l', 'o'});
  EXPECT_EQ(error_of([&] { Checkpoint::read(text); }),
            "checkpoint " + text.string() + " is truncated or not an HDF5 file");

  EXPECT_EQ(error_of([] { Checkpoint::read("/nonexistent/ck.h5"); }),
            "checkpoint /nonexistent/ck.h5: cannot read: No such file or directory");
}

TEST(Checkpoint, OtherFormatVersionIsRefused) {
  const fs::path p = scratch("v3.h5");
  sample().write(p);
  {
    hdf5::Handle f(H5Fopen(p.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
    ASSERT_TRUE(f.valid());
    ASSERT_GE(H5Adelete(f.get(), "immerse_checkpoint_format"), 0);
    ASSERT_TRUE(hdf5::write_attribute(f.get(), "immerse_checkpoint_format", std::int64_t{3}));
  }
  EXPECT_EQ(error_of([&] { Checkpoint::read(p); }),
            "checkpoint " + p.string() + " was written by format version 3, this program reads version 1");
}

TEST(Checkpoint, UnwritablePathLeavesNothing) {
  const fs::path blocker = scratch("plainfile");
  dump(blocker, {'x'});
  const fs::path p = blocker / "ck.h5";  // parent is a regular file: even root cannot create it
  EXPECT_EQ(error_of([&] { sample().write(p); }), "cannot write " + p.string() + ": Not a directory");
  EXPECT_EQ(error_of([] { sample().write("/proc/immerse_ck.h5"); }).rfind("cannot write /proc/immerse_ck.h5: ", 0), 0u);
}

TEST(Checkpoint, RejectsProgrammingErrors) {
  Checkpoint c;
  c.put_int("a", 1);
  EXPECT_THROW(c.put_double("a", 1.0), std::logic_error);
  EXPECT_THROW(c.put_double("x/y", 1.0), std::logic_error);
  EXPECT_THROW(c.put_array("b", {1, 2, 3}, {2, 2}), std::logic_error);
}
