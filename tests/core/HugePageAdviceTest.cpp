// Huge page advice: the policy's values, the decision, and the advice reaching the kernel (the
// mapping's VmFlags in /proc/self/smaps carry "hg" once advised MADV_HUGEPAGE); direct-I/O
// buffers (AlignedBuffer) of a huge page or more in whole, advised huge pages.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include "TestSupport.h"
#include "core/AlignedBuffer.h"
#include "core/AtomicFile.h"
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

TEST(HugePageAdvice, TheRememberedAdviceIsThisBootsOnlyAndAnythingElseIsMeasuredAgain) {
  testing::TempDir dir("advice");
  const std::filesystem::path file = dir / "cache/flipscope/huge-page-advice-host";
  EXPECT_EQ(rememberedAdvice(file, "boot-a"), std::nullopt);  // none yet
  const FirstTouchSeconds measured{.bytes = 4 << 20, .plainPages = 0.011, .hugePages = 0.0005};
  rememberAdvice(file, "boot-a", true, measured);
  EXPECT_EQ(rememberedAdvice(file, "boot-a"), true);
  EXPECT_EQ(rememberedAdvice(file, "boot-b"), std::nullopt);  // another boot
  EXPECT_EQ(rememberedAdvice(file, ""), std::nullopt);        // no boot id: nothing is remembered
  rememberAdvice(file, "boot-a", false, measured);
  EXPECT_EQ(rememberedAdvice(file, "boot-a"), false);
  EXPECT_NE(readTextFile(file, "advice").find("first touch of 4194304 bytes: 0.011 s in 4 KiB pages"),
            std::string::npos)
      << readTextFile(file, "advice");
  // Older than a day: measured again.
  std::filesystem::last_write_time(file, std::filesystem::file_time_type::clock::now() -
                                             std::chrono::seconds(static_cast<long>(kRememberedAdviceSeconds) + 60));
  EXPECT_EQ(rememberedAdvice(file, "boot-a"), std::nullopt);
  // Dated ahead of the clock: measured again too.
  rememberAdvice(file, "boot-a", true, measured);
  std::filesystem::last_write_time(file, std::filesystem::file_time_type::clock::now() + std::chrono::hours(2));
  EXPECT_EQ(rememberedAdvice(file, "boot-a"), std::nullopt);
  // Not the format: cut short, another header, another word.
  for (const char* text :
       {"flipscope huge page advice 1\nboot boot-a\n", "flipscope huge page advice 2\nboot boot-a\nadvice on\n",
        "flipscope huge page advice 1\nboot boot-a\nadvice yes\n"}) {
    writeTextAtomically(file, text);
    EXPECT_EQ(rememberedAdvice(file, "boot-a"), std::nullopt) << text;
  }
  // Not a few lines of text: a pipe that holds the right lines (read, it could as well wait for
  // ever), and a large file that starts right.
  ASSERT_EQ(::mkfifo((dir / "pipe").c_str(), 0600), 0);
  const int pipe = ::open((dir / "pipe").c_str(), O_RDWR | O_NONBLOCK);
  ASSERT_GE(pipe, 0);
  const std::string lines = "flipscope huge page advice 1\nboot boot-a\nadvice on\n";
  ASSERT_EQ(::write(pipe, lines.data(), lines.size()), ssize_t(lines.size()));
  EXPECT_EQ(rememberedAdvice(dir / "pipe", "boot-a"), std::nullopt);
  ::close(pipe);
  writeTextAtomically(file, "flipscope huge page advice 1\nboot boot-a\nadvice on\n" + std::string(8192, '#'));
  EXPECT_EQ(rememberedAdvice(file, "boot-a"), std::nullopt);
  // A place that cannot be written (its parent a file): nothing thrown, nothing remembered.
  writeTextAtomically(dir / "plain", "x");
  EXPECT_NO_THROW(rememberAdvice(dir / "plain/huge-page-advice-host", "boot-a", true, measured));
  EXPECT_EQ(rememberedAdvice(dir / "plain/huge-page-advice-host", "boot-a"), std::nullopt);
}

TEST(HugePageAdvice, TheCacheIsXdgCacheHomesWhenAbsoluteElseHomesAndNamedByHost) {
  testing::TempDir dir("advice-path");
  const testing::ScopedEnvironment home("HOME", (dir / "home").string());
  {
    const testing::ScopedEnvironment xdg("XDG_CACHE_HOME", (dir / "xdg").string());
    const auto path = rememberedAdvicePath();
    ASSERT_TRUE(path);
    EXPECT_EQ(path->parent_path(), dir / "xdg/flipscope");
    EXPECT_EQ(path->filename().string().rfind("huge-page-advice-", 0), 0u) << *path;
    EXPECT_GT(path->filename().string().size(), std::string("huge-page-advice-").size()) << *path;
  }
  {
    const testing::ScopedEnvironment xdg("XDG_CACHE_HOME", "relative/cache");  // ignored, as the spec says
    const auto path = rememberedAdvicePath();
    ASSERT_TRUE(path);
    EXPECT_EQ(path->parent_path(), dir / "home/.cache/flipscope");
  }
  const testing::ScopedEnvironment relativeHome("HOME", "relative");
  const testing::ScopedEnvironment xdg("XDG_CACHE_HOME", "");
  EXPECT_EQ(rememberedAdvicePath(), std::nullopt);
}

TEST(HugePageAdvice, ChoosingTakesThisBootsRememberedAdviceElseMeasuresAndRemembersIt) {
  if (!transparentHugePagesAvailable()) GTEST_SKIP() << "transparent huge pages are off on this machine";
  const std::string boot = currentBootId();
  if (boot.empty()) GTEST_SKIP() << "this machine has no boot id";
  testing::TempDir dir("advice-choose");
  const testing::ScopedEnvironment xdg("XDG_CACHE_HOME", dir.path().string());
  ::unsetenv("FLIPSCOPE_HUGE_PAGES");
  const auto file = rememberedAdvicePath();
  ASSERT_TRUE(file);
  // Whatever a measurement would say, each remembered value is taken as it is.
  for (const bool remembered : {true, false}) {
    rememberAdvice(*file, boot, remembered, {});
    EXPECT_EQ(chooseHugePageAdvice(), remembered);
  }
  // Another boot's: measured, and this boot's remembered.
  rememberAdvice(*file, boot + "-before", true, {});
  const bool measured = chooseHugePageAdvice();
  EXPECT_EQ(rememberedAdvice(*file, boot), measured);
  EXPECT_NE(readTextFile(*file, "advice").find("first touch of 4194304 bytes"), std::string::npos);
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

TEST(HugePageAdvice, DirectIoBuffersAskForHugePagesUnlessTheVariableSaysOff) {
  EXPECT_TRUE(alignedBuffersAskForHugePages(nullptr));
  EXPECT_TRUE(alignedBuffersAskForHugePages("auto"));
  EXPECT_TRUE(alignedBuffersAskForHugePages("on"));
  EXPECT_TRUE(alignedBuffersAskForHugePages("bogus")) << "main() reports it; a buffer does not throw";
  EXPECT_FALSE(alignedBuffersAskForHugePages("off"));
}

TEST(HugePageAdvice, ADirectIoBufferOfAHugePageOrMoreIsWholeAdvisedHugePages) {
  const bool asked = alignedBuffersAskForHugePages(std::getenv("FLIPSCOPE_HUGE_PAGES"));
  for (const std::size_t bytes : {kHugePageBytes, kHugePageBytes + 1, 3 * kHugePageBytes - 4096}) {
    AlignedBuffer buffer(bytes);
    ASSERT_NE(buffer.data(), nullptr);
    EXPECT_EQ(buffer.size(), (bytes + kDirectBlock - 1) / kDirectBlock * kDirectBlock);
    const auto address = reinterpret_cast<std::uintptr_t>(buffer.data());
    EXPECT_EQ(address % (asked ? kHugePageBytes : kDirectBlock), 0u) << bytes;
    std::memset(buffer.data(), 7, buffer.size());  // all of it is the buffer's
    if (asked && transparentHugePagesAvailable()) {
      // Whole huge pages: the last byte of the last one is advised too.
      const std::size_t whole = (buffer.size() + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
      EXPECT_NE(vmFlagsAt(buffer.data()).find(" hg"), std::string::npos) << vmFlagsAt(buffer.data());
      EXPECT_NE(vmFlagsAt(buffer.data() + whole - 1).find(" hg"), std::string::npos) << bytes;
    }
  }
  AlignedBuffer small(kHugePageBytes - kDirectBlock);  // under a huge page: blocks, as before
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(small.data()) % kDirectBlock, 0u);
  EXPECT_EQ(small.size(), kHugePageBytes - kDirectBlock);
}

TEST(HugePageAdvice, ADirectIoBufferPastThirtyTwoMegabytesFollowsTheProcesssAdvice) {
  if (!alignedBuffersAskForHugePages(std::getenv("FLIPSCOPE_HUGE_PAGES")) || !transparentHugePagesAvailable())
    GTEST_SKIP() << "direct-I/O buffers ask for no huge pages here (FLIPSCOPE_HUGE_PAGES=off, or THP off)";
  const bool before = hugePageAdviceOn();
  constexpr std::size_t kBytes = kAlwaysHugeBufferBytes + (std::size_t(8) << 20);  // a fresh mapping
  setHugePageAdvice(false);
  {
    AlignedBuffer buffer(kBytes);
    EXPECT_EQ(vmFlagsAt(buffer.data() + kBytes / 2).find(" hg"), std::string::npos) << vmFlagsAt(buffer.data());
  }
  setHugePageAdvice(true);
  {
    AlignedBuffer buffer(kBytes);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(buffer.data()) % kHugePageBytes, 0u);
    EXPECT_NE(vmFlagsAt(buffer.data() + kBytes / 2).find(" hg"), std::string::npos) << vmFlagsAt(buffer.data());
  }
  setHugePageAdvice(before);
}

}  // namespace
}  // namespace flipscope
