#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

#include "large_array.h"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace kdmesh {
namespace {

TEST(LargeArray, HoldsValuesAsAVector) {
  LargeArray<uint32_t> values;
  for (uint32_t i = 0; i < 3'000'000; ++i) values.push_back(i * 7);  // grows past the advice threshold
  ASSERT_EQ(values.size(), 3'000'000u);
  for (uint32_t i = 0; i < values.size(); i += 99'991) EXPECT_EQ(values[i], i * 7);
  LargeArray<uint32_t> copy = values;
  EXPECT_EQ(copy, values);
}

TEST(GrowingArray, KeepsItsValuesThroughGrowthAndMoves) {
  GrowingArray<uint32_t> values;
  EXPECT_EQ(values.size(), 0u);
  values.reserve(10);
  EXPECT_EQ(values.size(), 0u);  // reserving adds no values
  for (uint32_t i = 0; i < 3'000'000; ++i) values.push_back(i * 7);  // grows past the reserve and the advice threshold
  ASSERT_EQ(values.size(), 3'000'000u);
  for (uint32_t i = 0; i < values.size(); i += 99'991) ASSERT_EQ(values[i], i * 7);
  EXPECT_EQ(values.data()[2'999'999], 2'999'999u * 7);
  values.reserve(5);  // never shrinks
  EXPECT_EQ(values[2'999'999], 2'999'999u * 7);

  GrowingArray<uint32_t> moved(std::move(values));
  EXPECT_EQ(moved.size(), 3'000'000u);
  EXPECT_EQ(moved[12345], 12345u * 7);
  GrowingArray<uint32_t> assigned;
  assigned.push_back(1);
  assigned = std::move(moved);
  EXPECT_EQ(assigned.size(), 3'000'000u);
  EXPECT_EQ(assigned[3], 21u);
  assigned = GrowingArray<uint32_t>{};  // as a store's reset() empties its pools
  EXPECT_EQ(assigned.size(), 0u);
  assigned.push_back(9);
  EXPECT_EQ(assigned[0], 9u);
}

#if defined(__linux__) && defined(MADV_HUGEPAGE)
// The flags of the mapping that holds `address`, as /proc/self/smaps lists
// them ("VmFlags: rd wr mr ... hg"), or "" if not found.
std::string mappingFlags(const void* address) {
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  const uintptr_t at = uintptr_t(address);
  while (std::getline(smaps, line)) {
    uintptr_t low = 0, high = 0;
    char dash = 0;
    std::istringstream header(line);
    if (header >> std::hex >> low >> dash >> high && dash == '-') {
      inside = low <= at && at < high;
      continue;
    }
    if (inside && line.rfind("VmFlags:", 0) == 0) return line;
  }
  return "";
}

TEST(LargeArray, AsksForHugePagesForLargeAllocations) {
  // Whether this kernel has transparent huge pages to advise at all.
  void* probe = mmap(nullptr, size_t(4) << 20, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(probe, MAP_FAILED);
  const bool supported = madvise(probe, size_t(4) << 20, MADV_HUGEPAGE) == 0;
  munmap(probe, size_t(4) << 20);
  if (!supported) GTEST_SKIP() << "no transparent huge pages in this kernel";

  LargeArray<uint64_t> large(size_t(8) << 20);  // 64 MiB
  const std::string largeFlags = mappingFlags(large.data() + large.size() / 2);
  ASSERT_NE(largeFlags, "");
  EXPECT_NE(largeFlags.find(" hg"), std::string::npos) << largeFlags;

  LargeArray<uint64_t> small(1000);  // 8 KB: not advised
  const std::string smallFlags = mappingFlags(small.data());
  ASSERT_NE(smallFlags, "");
  EXPECT_EQ(smallFlags.find(" hg"), std::string::npos) << smallFlags;
}
#endif

}  // namespace
}  // namespace kdmesh
