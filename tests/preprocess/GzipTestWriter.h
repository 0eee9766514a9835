// gzip for the reader tests (zlib's deflate in gzip mode): one member, or the data split into
// several concatenated members (what `cat a.gz b.gz` makes).
#pragma once

#include <zlib.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace flipscope::testing {

inline std::string gzipMember(const std::string& data, int level = 6) {
  z_stream z{};
  if (deflateInit2(&z, level, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw std::runtime_error("deflateInit2");
  std::string out;
  std::vector<unsigned char> buffer(64 * 1024);
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  z.avail_in = uInt(data.size());
  int status;
  do {
    z.next_out = buffer.data();
    z.avail_out = uInt(buffer.size());
    status = deflate(&z, Z_FINISH);
    out.append(reinterpret_cast<const char*>(buffer.data()), buffer.size() - z.avail_out);
  } while (status != Z_STREAM_END);
  deflateEnd(&z);
  return out;
}

/// `data` gzipped as `members` concatenated members of about equal size.
inline std::string gzip(const std::string& data, int members = 1) {
  std::string out;
  const std::size_t piece = (data.size() + std::size_t(members) - 1) / std::size_t(members);
  for (int m = 0; m < members; ++m) {
    const std::size_t begin = std::min(data.size(), std::size_t(m) * piece);
    out += gzipMember(data.substr(begin, std::min(piece, data.size() - begin)));
  }
  return out;
}

}  // namespace flipscope::testing
