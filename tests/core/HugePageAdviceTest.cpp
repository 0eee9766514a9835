// Huge page advice: the policy's values, the decision, and the advice reaching the kernel (the
// mapping's VmFlags in /proc/self/smaps carry "hg" once advised MADV_HUGEPAGE).
#include <gtest/gtest.h>
#include <sys/mman.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

#include "core/Error.h"
#include "core/HugePageAdvice.h"

namespace flipscope {
namespace {

TEST(HugePageAdvice, ThePolicyIsOnOffOrAutoAndAnythingElseIsAnErrorNamingTheVariable) {
  EXPECT_EQ(hugePagePolicyFromEnvironment(nullptr), std::nullopt);
  EXPECT_EQ(hugePagePolicyFromEnvironment(""), std::nullopt);
  EXPECT_EQ(hugePagePolicyFromEnvironment("auto"), std::nullopt);
  EXPECT_EQ(hugePagePolicyFromEnvironment("on"), true);
  EXPECT_EQ(hugePagePolicyFromEnvironment("off"), false);
  try {
    hugePagePolicyFromEnvironment("yes");
    FAIL() << "took 'yes'";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "FLIPSCOPE_HUGE_PAGES: on, off or auto, not 'yes'");
  }
}

TEST(HugePageAdvice, AdvisedOnlyWherePlainPagesFillSlowlyAndHugePagesInHalfTheTime) {
  constexpr std::size_t kFourMiB = std::size_t(4) << 20;  // 1 GB/s: 4.19 ms
  EXPECT_TRUE(hugePagesWorthAdvising({.bytes = kFourMiB, .plainPages = 0.040, .hugePages = 0.002}));
  EXPECT_TRUE(hugePagesWorthAdvising({.bytes = kFourMiB, .plainPages = 0.040, .hugePages = 0.020}));
  EXPECT_FALSE(hugePagesWorthAdvising({.bytes = kFourMiB, .plainPages = 0.040, .hugePages = 0.021}));
  EXPECT_FALSE(hugePagesWorthAdvising({.bytes = kFourMiB, .plainPages = 0.005, .hugePages = 0.060}));
  // Plain pages at 3 GB/s (the VM where large advised buffers stall): no advice, however fast
  // the probe's huge pages were; just under 1 GB/s, advice.
  EXPECT_FALSE(hugePagesWorthAdvising({.bytes = kFourMiB, .plainPages = 0.0014, .hugePages = 0.0002}));
  EXPECT_FALSE(hugePagesWorthAdvising({.bytes = kFourMiB, .plainPages = 0.0041, .hugePages = 0.0002}));
  EXPECT_TRUE(hugePagesWorthAdvising({.bytes = kFourMiB, .plainPages = 0.0043, .hugePages = 0.0002}));
  EXPECT_FALSE(hugePagesWorthAdvising({.bytes = kFourMiB, .plainPages = 0.040, .hugePages = 0}));
  EXPECT_FALSE(hugePagesWorthAdvising({}));  // nothing measured
  const FirstTouchSeconds measured = measureFirstTouch(kFourMiB);
  EXPECT_EQ(measured.bytes, kFourMiB);
  EXPECT_GT(measured.plainPages, 0);
  EXPECT_GT(measured.hugePages, 0);
}

TEST(HugePageAdvice, ThePolicyVariableDecidesWithoutMeasuring) {
  for (const char* value : {"on", "off"}) {
    ::setenv("FLIPSCOPE_HUGE_PAGES", value, 1);
    EXPECT_EQ(chooseHugePageAdvice(), std::string(value) == "on");
    EXPECT_EQ(hugePageAdviceOn(), std::string(value) == "on");
  }
  ::setenv("FLIPSCOPE_HUGE_PAGES", "sometimes", 1);
  EXPECT_THROW(chooseHugePageAdvice(), InputError);
  ::unsetenv("FLIPSCOPE_HUGE_PAGES");
  setHugePageAdvice(false);
}

/// The VmFlags of the mapping that holds `p`, from /proc/self/smaps.
std::string vmFlagsAt(const void* p) {
  std::ifstream smaps("/proc/self/smaps");
  const auto address = reinterpret_cast<std::uintptr_t>(p);
  bool inside = false;
  for (std::string line; std::getline(smaps, line);) {
    std::uintptr_t begin = 0, end = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> begin >> dash >> end && dash == '-') {
      inside = begin <= address && address < end;
    } else if (inside && line.rfind("VmFlags:", 0) == 0) {
      return line;
    }
  }
  return {};
}

TEST(HugePageAdvice, AnAllocationsPagesAreAdvisedFromItsFirstPageOn) {
  if (!transparentHugePagesAvailable()) GTEST_SKIP() << "transparent huge pages are off on this machine";
  constexpr std::size_t kBytes = std::size_t(8) << 20;
  void* map = ::mmap(nullptr, kBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(map, MAP_FAILED);
  char* bytes = static_cast<char*>(map);
  ASSERT_NE(vmFlagsAt(bytes).find("VmFlags:"), std::string::npos);
  EXPECT_EQ(vmFlagsAt(bytes).find(" hg"), std::string::npos) << vmFlagsAt(bytes);
  // As malloc returns a large block: 16 bytes into its mapping.
  adviseHugePages(bytes + 16, kBytes - 16);
  EXPECT_NE(vmFlagsAt(bytes).find(" hg"), std::string::npos) << vmFlagsAt(bytes);
  EXPECT_NE(vmFlagsAt(bytes + kBytes - 1).find(" hg"), std::string::npos) << vmFlagsAt(bytes + kBytes - 1);
  ::munmap(map, kBytes);
}

}  // namespace
}  // namespace flipscope
