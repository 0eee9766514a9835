// Whether large allocations ask for transparent huge pages (madvise MADV_HUGEPAGE), chosen
// per machine, since what a page fault costs differs from one virtual machine to the next.
//
// Measured on the development machine's two kinds of 2-core VM (a C program writing one byte
// a page of a fresh 400 MB mapping): on one, 0.13 s in 4 KiB pages and 0.3 to 3.1 s advised;
// on the other, 1.03 s in 4 KiB pages and 0.03 to 0.7 s advised, where advising made a 20 M
// particle convert plus first image twice as fast. Neither choice suits both, so a command
// that allocates large buffers measures both kinds of first touch once, on a few megabytes,
// and advises only where plain pages fill slowly (under kSlowFirstTouchBytesPerSecond) and
// huge pages were at least twice as fast (chooseHugePageAdvice).
//
// Why the speed of plain pages decides, not only the ratio: on the first kind of VM a probe of a
// few megabytes finds huge pages 5x faster (they come from blocks freed lately), while a buffer
// of hundreds of megabytes draws blocks the host must back again, at 0.4 to 0.9 GB/s against
// plain pages' 3 GB/s (160 MB: 182 to 440 ms advised, 55 ms plain). Advice can save at most what
// plain pages cost, so it is worth that risk only where they are slow: 1 GB/s lies between the
// 0.4 GB/s of the VM where it paid and the 3 GB/s of the one where it did not. There
// (2026-12-06), the peer's 20 M particle convert took 705 to 753 ms without advice and 686 to
// 1003 ms (median 896) with the probe's advice, eight runs each, alternating. Huge pages are
// probed twice, and plain pages again where they look slow, the faster time kept, so one
// preemption does not decide.
//
// The probe costs 20 to 40 ms where plain pages are slow (on the VM of 2026-12-07 its two plain
// touches took 10 and 13 ms), and every command paid it: `bench render`'s convert plus first
// image twice. The measured choice is therefore remembered for the rest of the boot, for at most
// kRememberedAdviceSeconds, in a small file per host (rememberedAdvicePath): a 10 k particle
// convert took 0.07 s against 0.09 s measuring each time (eight runs each, alternating).
//
// FLIPSCOPE_HUGE_PAGES=on|off|auto (default auto: measure, or what this boot measured) overrides
// the measurement. Direct-I/O buffers (core/AlignedBuffer.h) of 2 to 32 MiB ask for huge pages
// whatever was measured, for their reads' sake; off turns that off too.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace flipscope {

/// A transparent huge page (x86-64). Allocations of at least this many bytes are advised while
/// advice is on: smaller ones cannot hold a whole one.
inline constexpr std::size_t kHugePageBytes = std::size_t(2) << 20;

/// Whether operator new advises the allocations of kHugePageBytes and more (the
/// flipscope executable's operator new reads it; see tools/LargeAllocations.cpp). Off until set.
bool hugePageAdviceOn();
void setHugePageAdvice(bool on);

/// Advises the pages of [p, p + bytes) MADV_HUGEPAGE. The kernel backs with huge pages only the
/// 2 MiB-aligned stretches inside one mapping; the rest is unchanged. Failure is ignored: advice.
void adviseHugePages(void* p, std::size_t bytes);

/// What the kernel does with MADV_HUGEPAGE here: false where transparent huge pages are off
/// (/sys/kernel/mm/transparent_hugepage/enabled says [never], or is missing).
bool transparentHugePagesAvailable();

/// Plain pages filling faster than this (bytes a second) get no advice: 1 GB/s, between the
/// 0.4 GB/s of the VM where advice pays and the 3 GB/s of the one where it does not.
inline constexpr double kSlowFirstTouchBytesPerSecond = 1e9;

/// The first touch of `bytes` of fresh memory, in seconds: in 4 KiB pages (the faster of two
/// where the first is under kSlowFirstTouchBytesPerSecond), and advised (the faster of two).
struct FirstTouchSeconds {
  std::size_t bytes = 0;
  double plainPages = 0;
  double hugePages = 0;
};
FirstTouchSeconds measureFirstTouch(std::size_t bytes);

/// Advice on when 4 KiB pages fill slower than kSlowFirstTouchBytesPerSecond and huge pages
/// touch at most half as long.
bool hugePagesWorthAdvising(const FirstTouchSeconds& measured);

/// FLIPSCOPE_HUGE_PAGES's value: true (on), false (off), nullopt (auto or unset). Throws
/// InputError, naming the variable, for another value.
std::optional<bool> hugePagePolicyFromEnvironment(const char* value);

/// How long a measured advice is taken as this machine's, within one boot: a day, so that a VM
/// moved to another host without a reboot is measured again.
inline constexpr double kRememberedAdviceSeconds = 24 * 3600;

/// Where the measured advice is remembered: `$XDG_CACHE_HOME/flipscope/huge-page-advice-<host>`
/// (an absolute XDG_CACHE_HOME only, as the XDG spec says), else under `$HOME/.cache`; nullopt
/// without either. Named by host, so that a home directory shared by a farm's nodes keeps one
/// file each.
std::optional<std::filesystem::path> rememberedAdvicePath();

/// This boot's id (/proc/sys/kernel/random/boot_id), empty where there is none.
std::string currentBootId();

/// The advice `file` remembers for boot `bootId`: nullopt where the file is missing, unreadable,
/// not in rememberAdvice's format, of another boot, older than kRememberedAdviceSeconds, or dated
/// in the future. Removing the file makes the next command measure again.
std::optional<bool> rememberedAdvice(const std::filesystem::path& file, std::string_view bootId);

/// Writes what rememberedAdvice reads (atomically; its directory created). Never throws: a cache
/// that cannot be written only means measuring again.
void rememberAdvice(const std::filesystem::path& file, std::string_view bootId, bool on,
                    const FirstTouchSeconds& measured);

/// Sets the advice for this process: as FLIPSCOPE_HUGE_PAGES says; else as this boot measured
/// (rememberedAdvice); else measured (measureFirstTouch of 4 MiB, about 10 to 40 ms) and
/// remembered. Returns what it chose.
bool chooseHugePageAdvice();

}  // namespace flipscope
