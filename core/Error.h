// Error reporting in three tiers (see STYLE.md):
//  - InputError / FileError: bad user input or a bad file; the message names the file, the
//    offset or field, and what was expected. Tools print it and exit with kExitBadInput.
//  - FLIPSCOPE_CHECK: programmer errors; always on, throws LogicError with both values.
//  - Recoverable oddities (NaN positions, particles outside the domain) are counted by the
//    code that meets them and reported, never thrown.
#pragma once

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>

namespace flipscope {

/// Exit codes of the flipscope command.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;   ///< verification failed, or an internal error
inline constexpr int kExitUsage = 2;     ///< bad command line
inline constexpr int kExitBadInput = 3;  ///< unreadable, truncated or corrupted input file
inline constexpr int kExitOutput = 4;    ///< an output cannot be created or written
inline constexpr int kExitNotConverged = 5;  ///< a render stopped at its pass limit (images written)

/// Bad input from the user (command line values, inconsistent options).
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// `text` with NUL and the other control bytes (but line breaks and tabs) written as \xNN, so
/// that a message quoting bytes of a file is printed whole (C strings end at a NUL).
inline std::string printableText(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if ((byte < 0x20 && c != '\n' && c != '\t') || byte == 0x7f) {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[byte >> 4];
      out += kHex[byte & 15];
    } else {
      out += c;
    }
  }
  return out;
}

/// The text of the current errno (strerror), for the messages of failed system calls. Call it
/// at once after the call: anything between may change errno.
inline std::string errnoText() { return std::strerror(errno); }

/// A file that cannot be read or written, or whose content is malformed.
/// what() reads "<path>: <reason>", the reason made printable (printableText).
class FileError : public InputError {
 public:
  FileError(const std::filesystem::path& path, const std::string& reason)
      : InputError(path.string() + ": " + printableText(reason)), mPath(path), mReason(printableText(reason)) {}
  const std::filesystem::path& path() const { return mPath; }
  /// what() without the path.
  const std::string& reason() const { return mReason; }

 private:
  std::filesystem::path mPath;
  std::string mReason;
};

/// An output that cannot be created or written (a missing or read-only directory, a full
/// disk). Tools exit with kExitOutput.
class OutputError : public FileError {
 public:
  using FileError::FileError;
};

/// A violated internal invariant.
class LogicError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

namespace detail {
[[noreturn]] inline void checkFailed(const char* expr, const char* file, int line, const std::string& msg) {
  std::ostringstream os;
  os << file << ":" << line << ": check failed: " << expr;
  if (!msg.empty()) os << " (" << msg << ")";
  throw LogicError(os.str());
}
}  // namespace detail

}  // namespace flipscope

/// Always-on invariant check: FLIPSCOPE_CHECK(a == b, "a=" << a << " b=" << b).
#define FLIPSCOPE_CHECK(cond, ...)                                                            \
  do {                                                                                        \
    if (!(cond)) {                                                                            \
      std::ostringstream flipscope_check_os_;                                                 \
      (void)(flipscope_check_os_ __VA_OPT__(<< __VA_ARGS__));                                 \
      ::flipscope::detail::checkFailed(#cond, __FILE__, __LINE__, flipscope_check_os_.str()); \
    }                                                                                         \
  } while (0)
