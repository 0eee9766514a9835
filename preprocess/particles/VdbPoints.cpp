// OpenVDB point files written through OpenVDB: one PointDataGrid 'particles' with P (and the
// velocity `v` when asked), stored as io::Stream writes it. The writing itself is OpenVDB's, in
// a module loaded here on first use (VdbWriterModule.h: libflipscope_vdb_writer.so); this side
// gathers the particles and owns the file. Reading is VdbPointsReader.cpp, our own
// bounds-checked decoder; OpenVDB's reader is only the oracle of its tests.
#include <dlfcn.h>

#include <cmath>
#include <mutex>
#include <ostream>
#include <streambuf>
#include <string>
#include <vector>

#include "core/AtomicFile.h"
#include "core/Error.h"
#include "preprocess/particles/ParticleFormats.h"
#include "preprocess/particles/VdbWriterModule.h"

namespace flipscope::detail {
namespace {

/// The module's WriteFunction, loaded once: from beside the running binary, else from the build
/// tree this code was built in (the tests' binaries lie below it). Throws `OutputError` naming
/// `destination`, the places looked in and why the loader refused, when neither loads.
vdbwriter::WriteFunction writeFunction(const std::filesystem::path& destination) {
  static std::once_flag once;
  static vdbwriter::WriteFunction function = nullptr;
  static std::string refused;
  std::call_once(once, [] {
    std::vector<std::filesystem::path> places;
    std::error_code ec;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) places.push_back(self.parent_path() / vdbwriter::kModuleFile);
    const std::filesystem::path built = std::filesystem::path(FLIPSCOPE_BUILD_DIR) / vdbwriter::kModuleFile;
    if (places.empty() || places.front() != built) places.push_back(built);
    for (const auto& place : places) {
      void* module = ::dlopen(place.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!module) {
        const char* why = ::dlerror();
        refused += (refused.empty() ? "" : "; ") + std::string(why ? why : place.string() + ": not loaded");
        continue;
      }
      function = reinterpret_cast<vdbwriter::WriteFunction>(::dlsym(module, vdbwriter::kEntryPoint));
      if (function) return;  // the module stays loaded
      refused += (refused.empty() ? "" : "; ") + place.string() + " has no " + vdbwriter::kEntryPoint;
      ::dlclose(module);
    }
  });
  if (!function)
    throw OutputError(destination, std::string("writing OpenVDB points needs ") + vdbwriter::kModuleFile +
                                       " beside the flipscope binary (" + refused + ")");
  return function;
}

/// Unbuffered std::streambuf that appends to an AtomicFile (which buffers itself).
class AtomicFileStreamBuffer final : public std::streambuf {
 public:
  explicit AtomicFileStreamBuffer(AtomicFile& file) : mFile(file) {}

 protected:
  std::streamsize xsputn(const char* data, std::streamsize count) override {
    mFile.write(data, static_cast<std::size_t>(count));
    return count;
  }
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    char byte = traits_type::to_char_type(c);
    mFile.write(&byte, 1);
    return c;
  }

 private:
  AtomicFile& mFile;
};

class VdbPointsWriter final : public ParticleWriter {
 public:
  VdbPointsWriter(const std::filesystem::path& path, const WriteOptions& options) : mFile(path), mOptions(options) {
    writeFunction(path);  // a missing module says so before any particle is gathered
  }

  void write(const ParticleChunk& chunk) override {
    FLIPSCOPE_CHECK(!mOptions.velocity || chunk.velocities.size() == chunk.size(),
                    "velocities=" << chunk.velocities.size() << " positions=" << chunk.size());
    for (std::size_t k = 0; k < chunk.size(); ++k) {
      const glm::vec3& p = chunk.positions[k];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw InputError(mFile.destination().string() +
                         ": OpenVDB points cannot store the non-finite position of particle " +
                         std::to_string(mPositions.size()));
      mPositions.push_back(p);
      if (mOptions.velocity) mVelocities.push_back(chunk.velocities[k]);
    }
  }

  void commit() override {
    static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
    vdbwriter::Points points;
    points.positions = reinterpret_cast<const float*>(mPositions.data());
    points.velocities = reinterpret_cast<const float*>(mVelocities.data());
    points.count = mPositions.size();
    points.velocity = mOptions.velocity;
    points.voxelSize = mOptions.vdbVoxelSize;
    AtomicFileStreamBuffer buffer(mFile);
    std::ostream stream(&buffer);
    stream.exceptions(std::ios::badbit | std::ios::failbit);
    char error[512] = {};
    if (!writeFunction(mFile.destination())(points, stream, error, sizeof error))
      throw InputError(mFile.destination().string() + ": " + error);
    stream.flush();
    mFile.commit();
  }

 private:
  AtomicFile mFile;
  WriteOptions mOptions;
  std::vector<glm::vec3> mPositions;
  std::vector<glm::vec3> mVelocities;
};

}  // namespace

std::unique_ptr<ParticleWriter> createVdbWriter(const std::filesystem::path& path, const WriteOptions& options) {
  return std::make_unique<VdbPointsWriter>(path, options);
}

}  // namespace flipscope::detail
