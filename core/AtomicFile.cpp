#include "core/AtomicFile.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>

#include "core/Error.h"

namespace flipscope {
namespace {
std::string errnoText() { return std::strerror(errno); }
std::atomic<unsigned> gTemporaryCounter{0};
}  // namespace

AtomicFile::AtomicFile(std::filesystem::path destination) : mDestination(std::move(destination)) {
  auto dir = mDestination.parent_path();
  if (dir.empty()) dir = ".";
  mTemporary = dir / ("." + mDestination.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                      std::to_string(gTemporaryCounter++));
  mFile = std::fopen(mTemporary.c_str(), "wb");
  if (!mFile) throw FileError(mTemporary, "cannot create temporary file: " + errnoText());
  std::setvbuf(mFile, nullptr, _IOFBF, 1 << 20);
}

AtomicFile::~AtomicFile() {
  if (mFile) {
    std::fclose(mFile);
    std::error_code ec;
    std::filesystem::remove(mTemporary, ec);
  }
}

void AtomicFile::write(const void* data, std::size_t bytes) {
  FLIPSCOPE_CHECK(mFile, "write after commit");
  if (bytes && std::fwrite(data, 1, bytes, mFile) != bytes) throw FileError(mTemporary, "write failed: " + errnoText());
  mOffset += bytes;
}

void AtomicFile::writeAt(std::uint64_t offset, const void* data, std::size_t bytes) {
  FLIPSCOPE_CHECK(mFile, "write after commit");
  FLIPSCOPE_CHECK(offset + bytes <= mOffset, "offset=" << offset << " bytes=" << bytes << " written=" << mOffset);
  if (::fseeko(mFile, static_cast<off_t>(offset), SEEK_SET) != 0 ||
      (bytes && std::fwrite(data, 1, bytes, mFile) != bytes) ||
      ::fseeko(mFile, static_cast<off_t>(mOffset), SEEK_SET) != 0)
    throw FileError(mTemporary, "write at byte " + std::to_string(offset) + " failed: " + errnoText());
}

void AtomicFile::commit() {
  FLIPSCOPE_CHECK(mFile, "commit twice");
  if (std::fflush(mFile) != 0) throw FileError(mTemporary, "flush failed: " + errnoText());
  if (::fsync(::fileno(mFile)) != 0) throw FileError(mTemporary, "fsync failed: " + errnoText());
  std::fclose(mFile);
  mFile = nullptr;
  if (std::rename(mTemporary.c_str(), mDestination.c_str()) != 0) {
    auto reason = errnoText();
    std::error_code ec;
    std::filesystem::remove(mTemporary, ec);
    throw FileError(mDestination, "cannot rename temporary file into place: " + reason);
  }
  auto dir = mDestination.parent_path();
  syncDirectory(dir.empty() ? std::filesystem::path(".") : dir);
}

void writeFileAtomically(const std::filesystem::path& destination, std::span<const std::byte> bytes) {
  AtomicFile file(destination);
  file.write(bytes);
  file.commit();
}

std::vector<std::byte> readFile(const std::filesystem::path& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw FileError(path, "cannot open: " + errnoText());
  std::vector<std::byte> bytes;
  std::byte buffer[1 << 16];
  for (;;) {
    std::size_t n = std::fread(buffer, 1, sizeof buffer, f);
    bytes.insert(bytes.end(), buffer, buffer + n);
    if (n < sizeof buffer) break;
  }
  bool failed = std::ferror(f);
  std::fclose(f);
  if (failed) throw FileError(path, "read failed");
  return bytes;
}

void syncDirectory(const std::filesystem::path& dir) {
  int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd < 0) return;  // best effort: some filesystems refuse to open directories
  ::fsync(fd);
  ::close(fd);
}

}  // namespace flipscope
