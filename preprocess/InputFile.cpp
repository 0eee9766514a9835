#include "preprocess/InputFile.h"

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

InputFile::~InputFile() { std::fclose(mFile); }

void InputFile::seek(std::uint64_t offset) {
  if (::fseeko(mFile, static_cast<off_t>(offset), SEEK_SET) != 0)
    throw FileError(mPath, "cannot seek to byte " + std::to_string(offset) + ": " + std::strerror(errno));
  mOffset = offset;
}

std::size_t InputFile::read(void* data, std::size_t bytes) {
  std::size_t n = std::fread(data, 1, bytes, mFile);
  if (n < bytes && std::ferror(mFile))
    throw FileError(mPath, "read failed at byte " + std::to_string(mOffset + n) + ": " + std::strerror(errno));
  mOffset += n;
  return n;
}

bool InputFile::readLine(std::string& line, std::size_t maxLength) {
  line.clear();
  for (;;) {
    int c = getc_unlocked(mFile);
    if (c == EOF) {
      if (std::ferror(mFile)) throw FileError(mPath, "read failed at byte " + std::to_string(mOffset));
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
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return true;
}

}  // namespace flipscope
