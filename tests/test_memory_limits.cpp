// The memory limits a run honours: a cgroup's limit is the smallest along its path to the root of the hierarchy
// ("max" and v1's huge "no limit" values are none); this process's limits include its physical memory.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include <unistd.h>

#include "immerse/core/MemoryLimits.hpp"

using namespace immerse;
namespace fs = std::filesystem;

namespace {

struct FakeHierarchy {
  fs::path root = fs::temp_directory_path() / ("immerse_cgroup_" + std::to_string(::getpid()));
  FakeHierarchy() { fs::create_directories(root / "user.slice" / "job"); }
  ~FakeHierarchy() { fs::remove_all(root); }
  void write(const fs::path& dir, const std::string& file, const std::string& text) const {
    std::ofstream(root / dir / file) << text << "\n";
  }
};

}  // namespace

TEST(MemoryLimits, ACgroupLimitIsTheSmallestAlongItsPath) {
  const FakeHierarchy h;
  h.write("", "memory.max", "max");
  h.write("user.slice", "memory.max", "2000000000");
  h.write("user.slice/job", "memory.max", "max");
  const auto limit = cgroup_memory_limit(h.root.string(), "/user.slice/job", "memory.max");
  ASSERT_TRUE(limit.has_value());
  EXPECT_EQ(limit->bytes, 2e9);
  EXPECT_EQ(limit->what, "the cgroup memory limit (2 GB, " + (h.root / "user.slice/memory.max").string() + ")");
  h.write("user.slice/job", "memory.max", "500000000");
  EXPECT_EQ(cgroup_memory_limit(h.root.string(), "/user.slice/job", "memory.max")->bytes, 5e8);
}

TEST(MemoryLimits, NoLimitWhereEveryLevelSaysNone) {
  const FakeHierarchy h;
  h.write("", "memory.limit_in_bytes", "9223372036854771712");  // cgroup v1: no limit
  h.write("user.slice", "memory.limit_in_bytes", "9223372036854771712");
  EXPECT_FALSE(cgroup_memory_limit(h.root.string(), "/user.slice/job", "memory.limit_in_bytes").has_value());
  EXPECT_FALSE(cgroup_memory_limit(h.root.string(), "/user.slice/job", "memory.max").has_value());  // no files
}

TEST(MemoryLimits, ThisProcessHasItsMachinesMemoryAmongItsLimits) {
  const auto limits = memory_limits();
  ASSERT_FALSE(limits.empty());
  EXPECT_EQ(limits[0].what.rfind("this machine's memory (", 0), 0u);
  EXPECT_GT(limits[0].bytes, 1e8);
  EXPECT_EQ(gigabytes(4.19e9), "4.19 GB");
}

TEST(MemoryLimits, PeakResidentMemoryGrowsWithWhatThisProcessTouches) {
  const auto before = peak_resident_bytes();
  ASSERT_TRUE(before.has_value());
  EXPECT_GT(*before, 1e6);
  // 64 MB written page by page is resident at once: the peak rises by about that much.
  std::vector<char> block(64u << 20);
  for (std::size_t i = 0; i < block.size(); i += 4096) block[i] = static_cast<char>(i);
  const auto after = peak_resident_bytes();
  ASSERT_TRUE(after.has_value());
  EXPECT_EQ(block[8192], static_cast<char>(8192 % 256));
  EXPECT_GE(*after, *before + 0.9 * double(block.size())) << *before;
}
