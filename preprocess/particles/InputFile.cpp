#include "preprocess/particles/InputFile.h"

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "core/Error.h"

namespace flipscope {

InputFile::InputFile(std::filesystem::path path) : mPath(std::move(path)) {
  std::error_code ec;
  if (std::filesystem::is_directory(mPath, ec)) throw FileError(mPath, "is a directory, expected a particle file");
  mFile = std::fopen(mPath.c_str(), "rb");
  if (!mFile) throw FileError(mPath, std::string("cannot open: ") + std::strerror(errno));
  std::setvbuf(mFile, nullptr, _IOFBF, 1 << 20);
  mSize = std::filesystem::file_size(mPath, ec);
  if (ec) {
    std::fclose(mFile);
    throw FileError(mPath, "cannot read the file size: " + ec.message());
  }
}

InputFile::InputFile(std::filesystem::path name, std::span<const std::byte> bytes)
    : mPath(std::move(name)), mMemory(bytes), mSize(bytes.size()) {}

InputFile::InputFile(InputFile&& other) noexcept
    : mPath(std::move(other.mPath)),
      mFile(std::exchange(other.mFile, nullptr)),
      mMemory(other.mMemory),
      mSize(other.mSize),
      mOffset(other.mOffset),
      mLineTerminated(other.mLineTerminated) {}

InputFile::~InputFile() {
  if (mFile) std::fclose(mFile);
}

void InputFile::seek(std::uint64_t offset) {
  if (!mFile) {
    if (offset > mSize) throw FileError(mPath, "cannot seek to byte " + std::to_string(offset) + ": past the end");
    mOffset = offset;
    return;
  }
  if (::fseeko(mFile, static_cast<off_t>(offset), SEEK_SET) != 0)
    throw FileError(mPath, "cannot seek to byte " + std::to_string(offset) + ": " + std::strerror(errno));
  mOffset = offset;
}

std::size_t InputFile::read(void* data, std::size_t bytes) {
  if (!mFile) {
    const std::size_t n = std::size_t(std::min<std::uint64_t>(bytes, mSize - mOffset));
    if (n) std::memcpy(data, mMemory.data() + mOffset, n);
    mOffset += n;
    return n;
  }
  std::size_t n = std::fread(data, 1, bytes, mFile);
  if (n < bytes && std::ferror(mFile))
    throw FileError(mPath, "read failed at byte " + std::to_string(mOffset + n) + ": " + std::strerror(errno));
  mOffset += n;
  return n;
}

int InputFile::get() {
  if (!mFile) return mOffset < mSize ? static_cast<int>(static_cast<unsigned char>(mMemory[mOffset])) : EOF;
  int c = getc_unlocked(mFile);
  if (c == EOF && std::ferror(mFile)) throw FileError(mPath, "read failed at byte " + std::to_string(mOffset));
  return c;
}

bool InputFile::readLine(std::string& line, std::size_t maxLength) {
  line.clear();
  mLineTerminated = false;
  for (;;) {
    int c = get();
    if (c == EOF) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      return !line.empty();
    }
    ++mOffset;
    if (c == '\n') break;
    if (line.size() == maxLength)
      throw FileError(mPath, "line at byte " + std::to_string(mOffset - line.size() - 1) + " is longer than " +
                                 std::to_string(maxLength) + " bytes");
    line.push_back(static_cast<char>(c));
  }
  mLineTerminated = true;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return true;
}

}  // namespace flipscope
