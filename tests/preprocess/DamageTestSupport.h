// Damage tests shared by the reader tests: a file cut at every length must be refused with a
// FileError (never a shorter valid read, never a crash), and a file with any single byte changed
// must be read or refused with a FileError, nothing else.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <span>
#include <string>

#include "TestSupport.h"
#include "core/Error.h"
#include "preprocess/particles/ParticleFormatRegistry.h"
#include "preprocess/particles/ParticleSource.h"

namespace flipscope::testing {

/// Every how many bytes the sweeps below (and VdbDamageTest's) change or cut a file: 1, every
/// byte, unless FLIPSCOPE_DAMAGE_STRIDE says otherwise. tests/run-asan.sh sweeps every 4th byte
/// under the sanitizers, 4x faster; the plain run and the fuzzers cover the rest.
inline std::size_t damageSweepStride() {
  return std::size_t(positiveCountFromEnvironment("FLIPSCOPE_DAMAGE_STRIDE", 1));
}

/// Opens `bytes` as the file `name` and reads every particle, with every attribute, twice
/// (rewind between). Returns the particle count.
inline std::size_t readBytesCompletely(const std::string& name, const std::string& bytes) {
  ReadOptions options;
  options.allAttributes = true;
  auto source = openParticleBytes(name, std::as_bytes(std::span(bytes.data(), bytes.size())), options);
  std::size_t total = 0;
  ParticleChunk chunk;
  for (int pass = 0; pass < 2; ++pass) {
    total = 0;
    while (source->read(chunk, 97)) total += chunk.size();
    source->rewind();
  }
  return total;
}

/// Every proper prefix of `bytes` (from `from` bytes on) is refused with a FileError.
inline void expectEveryTruncationRefused(const std::string& name, const std::string& bytes, std::size_t from = 0) {
  for (std::size_t length = from; length < bytes.size(); length += damageSweepStride()) {
    try {
      const std::size_t read = readBytesCompletely(name, bytes.substr(0, length));
      ADD_FAILURE() << name << " cut to " << length << " of " << bytes.size() << " bytes was read (" << read
                    << " particles) instead of refused";
    } catch (const FileError&) {
    }
  }
}

/// Each byte of `bytes` replaced by a few other values: read or refused with a FileError.
/// Returns how many of the damaged files were refused.
inline std::size_t expectCorruptionsHandled(const std::string& name, const std::string& bytes) {
  std::size_t refused = 0;
  for (std::size_t at = 0; at < bytes.size(); at += damageSweepStride())
    for (unsigned char change : {0x01, 0x80, 0xff, 0x5a}) {
      std::string damaged = bytes;
      damaged[at] = char(static_cast<unsigned char>(damaged[at]) ^ change);
      try {
        (void)readBytesCompletely(name, damaged);
      } catch (const FileError&) {
        ++refused;
      } catch (const std::exception& e) {
        ADD_FAILURE() << name << " with byte " << at << " xor " << int(change) << ": " << e.what();
      }
    }
  return refused;
}

}  // namespace flipscope::testing
