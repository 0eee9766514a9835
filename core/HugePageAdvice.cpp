#include "core/HugePageAdvice.h"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/AtomicFile.h"
#include "core/Elapsed.h"
#include "core/Error.h"

namespace flipscope {
namespace {

std::atomic<bool> gAdvice{false};

/// Seconds to write one byte a page of a fresh mapping of `bytes` (2 MiB-aligned), advised or not.
double touchFresh(std::size_t bytes, bool advised) {
  constexpr std::uintptr_t kHugePage = kHugePageBytes;
  const std::size_t mapped = bytes + kHugePage;
  void* map = ::mmap(nullptr, mapped, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (map == MAP_FAILED) return 0;
  auto* begin =
      reinterpret_cast<volatile char*>((reinterpret_cast<std::uintptr_t>(map) + kHugePage - 1) & ~(kHugePage - 1));
  if (advised) ::madvise(const_cast<char*>(begin), bytes, MADV_HUGEPAGE);
  const std::size_t page = std::size_t(::sysconf(_SC_PAGESIZE));
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < bytes; i += page) begin[i] = 1;
  const double seconds = secondsSince(start);
  ::munmap(map, mapped);
  return seconds;
}

}  // namespace

bool hugePageAdviceOn() { return gAdvice.load(std::memory_order_relaxed); }

void setHugePageAdvice(bool on) { gAdvice.store(on, std::memory_order_relaxed); }

void adviseHugePages(void* p, std::size_t bytes) {
  const std::uintptr_t page = std::uintptr_t(::sysconf(_SC_PAGESIZE));
  const std::uintptr_t begin = reinterpret_cast<std::uintptr_t>(p) & ~(page - 1);
  const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(p) + bytes + page - 1) & ~(page - 1);
  ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
}

bool transparentHugePagesAvailable() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  return std::getline(in, modes) && modes.find("[never]") == std::string::npos;
}

namespace {
bool plainPagesSlow(std::size_t bytes, double seconds) {
  return double(bytes) < kSlowFirstTouchBytesPerSecond * seconds;
}
}  // namespace

FirstTouchSeconds measureFirstTouch(std::size_t bytes) {
  FirstTouchSeconds s;
  s.bytes = bytes;
  s.plainPages = touchFresh(bytes, false);
  // A preemption can only slow a probe: plain pages that look slow get a second look (fast ones,
  // no advice whatever the rest, need none at each command's start).
  if (plainPagesSlow(bytes, s.plainPages)) s.plainPages = std::min(s.plainPages, touchFresh(bytes, false));
  s.hugePages = std::min(touchFresh(bytes, true), touchFresh(bytes, true));
  return s;
}

bool hugePagesWorthAdvising(const FirstTouchSeconds& measured) {
  return plainPagesSlow(measured.bytes, measured.plainPages) && measured.hugePages > 0 &&
         2 * measured.hugePages <= measured.plainPages;
}

std::optional<bool> hugePagePolicyFromEnvironment(const char* value) {
  if (!value) return std::nullopt;
  const std::string v = value;
  if (v == "on") return true;
  if (v == "off") return false;
  if (v == "auto" || v.empty()) return std::nullopt;
  throw InputError("FLIPSCOPE_HUGE_PAGES: on, off or auto, not '" + v + "'");
}

namespace {
/// The first line of a remembered advice file.
constexpr std::string_view kRememberedAdviceHeader = "flipscope huge page advice 1";
/// A remembered advice file is at most this long (it is about 150 bytes).
constexpr std::uintmax_t kRememberedAdviceBytes = 4096;

/// `name` with every character but letters, digits, '.', '-' and '_' made '_'.
std::string fileNamePart(std::string name) {
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '-' && c != '_') c = '_';
  return name;
}
}  // namespace

std::optional<std::filesystem::path> rememberedAdvicePath() {
  std::filesystem::path cache;
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  const char* home = std::getenv("HOME");
  if (xdg && std::filesystem::path(xdg).is_absolute()) {
    cache = xdg;
  } else if (home && std::filesystem::path(home).is_absolute()) {
    cache = std::filesystem::path(home) / ".cache";
  } else {
    return std::nullopt;
  }
  char host[256] = {};
  if (::gethostname(host, sizeof host - 1) != 0 || host[0] == 0) return std::nullopt;
  return cache / "flipscope" / ("huge-page-advice-" + fileNamePart(host));
}

std::string currentBootId() {
  std::ifstream in("/proc/sys/kernel/random/boot_id");
  std::string id;
  std::getline(in, id);
  return id;
}

std::optional<bool> rememberedAdvice(const std::filesystem::path& file, std::string_view bootId) {
  if (bootId.empty()) return std::nullopt;
  std::error_code ec;
  const auto written = std::filesystem::last_write_time(file, ec);
  if (ec) return std::nullopt;
  // A file dated ahead of this clock (a server's clock, `touch -d`) is no younger for it.
  const double age = std::chrono::duration<double>(std::filesystem::file_time_type::clock::now() - written).count();
  if (age < 0 || age > kRememberedAdviceSeconds) return std::nullopt;
  // A few lines of text: anything else (a device, a link to one, a large file) is not read.
  if (!std::filesystem::is_regular_file(file, ec) || std::filesystem::file_size(file, ec) > kRememberedAdviceBytes ||
      ec)
    return std::nullopt;
  std::ifstream in(file);
  std::string header, boot, advice;
  if (!std::getline(in, header) || !std::getline(in, boot) || !std::getline(in, advice)) return std::nullopt;
  if (header != kRememberedAdviceHeader || boot != "boot " + std::string(bootId)) return std::nullopt;
  if (advice == "advice on") return true;
  if (advice == "advice off") return false;
  return std::nullopt;
}

void rememberAdvice(const std::filesystem::path& file, std::string_view bootId, bool on,
                    const FirstTouchSeconds& measured) {
  try {
    std::filesystem::create_directories(file.parent_path());
    std::ostringstream text;
    text << kRememberedAdviceHeader << "\nboot " << bootId << "\nadvice " << (on ? "on" : "off") << "\nfirst touch of "
         << measured.bytes << " bytes: " << measured.plainPages << " s in 4 KiB pages, " << measured.hugePages
         << " s advised\n";
    writeTextAtomically(file, text.str());
  } catch (const std::exception&) {
    // Measured again by the next command.
  }
}

bool chooseHugePageAdvice() {
  const std::optional<bool> asked = hugePagePolicyFromEnvironment(std::getenv("FLIPSCOPE_HUGE_PAGES"));
  bool on = false;
  if (asked) {
    on = *asked;
  } else if (transparentHugePagesAvailable()) {
    const std::optional<std::filesystem::path> memo = rememberedAdvicePath();
    const std::string boot = currentBootId();
    const std::optional<bool> remembered = memo ? rememberedAdvice(*memo, boot) : std::nullopt;
    if (remembered) {
      on = *remembered;
    } else {
      const FirstTouchSeconds measured = measureFirstTouch(kHugePageBytes * 2);
      on = hugePagesWorthAdvising(measured);
      if (memo && !boot.empty()) rememberAdvice(*memo, boot, on, measured);
    }
  }
  setHugePageAdvice(on);
  return on;
}

}  // namespace flipscope
