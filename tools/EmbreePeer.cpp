#include "tools/EmbreePeer.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>

#include <tbb/parallel_for.h>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#if FLIPSCOPE_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

#include "core/AtomicFile.h"
#include "core/Elapsed.h"
#include "core/Error.h"
#include "core/ProcessMemory.h"
#include "pipeline/ImageWriter.h"
#include "preprocess/particles/ParticleSource.h"
#include "raycast/Camera.h"
#include "tools/BenchFrameStage.h"
#include "tools/ChildProcess.h"
#include "tools/CliValues.h"

namespace flipscope::tools {
namespace {

namespace fs = std::filesystem;

struct EmbreeStageArgs {
  EmbreeStageRequest request;
  std::string particles, cameraFile, statsFile, image;
};

#if FLIPSCOPE_HAVE_EMBREE

using Clock = std::chrono::steady_clock;

/// Embree's own allocations, through its memory monitor.
struct EmbreeMemory {
  std::atomic<std::int64_t> now{0};
  std::atomic<std::int64_t> peak{0};
  static bool monitor(void* self, std::ptrdiff_t bytes, bool /*post*/) {
    auto* m = static_cast<EmbreeMemory*>(self);
    const std::int64_t value = m->now += bytes;
    std::int64_t peak = m->peak;
    while (value > peak && !m->peak.compare_exchange_weak(peak, value)) {
    }
    return true;
  }
};

/// One frame of primary rays in 4x4 packets, rows of packets over the cores, shaded into
/// `image` (a head-lit grey picture of the hits, 0 elsewhere); returns the hits.
std::uint64_t traceFrame(RTCScene scene, const Camera& camera, std::uint32_t width, std::uint32_t height,
                         RenderImage& image) {
  const std::uint32_t packetsX = (width + 3) / 4, packetsY = (height + 3) / 4;
  std::atomic<std::uint64_t> hits{0};
  tbb::parallel_for(std::uint32_t(0), packetsY, [&](std::uint32_t py) {
    std::uint64_t rowHits = 0;
    for (std::uint32_t px = 0; px < packetsX; ++px) {
      alignas(64) RTCRayHit16 rays{};  // rtcIntersect16 wants both 64-byte aligned
      alignas(64) int valid[16];
      for (int i = 0; i < 16; ++i) {
        const std::uint32_t x = px * 4 + std::uint32_t(i % 4), y = py * 4 + std::uint32_t(i / 4);
        valid[i] = x < width && y < height ? -1 : 0;
        const glm::dvec3 d =
            camera.pixelRay(double(std::min(x, width - 1)), double(std::min(y, height - 1)), width, height);
        rays.ray.org_x[i] = float(camera.eye.x);
        rays.ray.org_y[i] = float(camera.eye.y);
        rays.ray.org_z[i] = float(camera.eye.z);
        rays.ray.dir_x[i] = float(d.x);
        rays.ray.dir_y[i] = float(d.y);
        rays.ray.dir_z[i] = float(d.z);
        rays.ray.tnear[i] = 0;
        rays.ray.tfar[i] = std::numeric_limits<float>::infinity();
        rays.ray.mask[i] = ~0u;
        rays.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      }
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      rtcIntersect16(valid, scene, &context, &rays);
      for (int i = 0; i < 16; ++i) {
        if (!valid[i]) continue;
        const std::uint32_t x = px * 4 + std::uint32_t(i % 4), y = py * 4 + std::uint32_t(i / 4);
        if (rays.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) {
          image.rgba[std::size_t(y) * width + x] = glm::vec4(0);
          continue;
        }
        ++rowHits;
        const glm::vec3 n = glm::normalize(glm::vec3(rays.hit.Ng_x[i], rays.hit.Ng_y[i], rays.hit.Ng_z[i]));
        const glm::vec3 d(rays.ray.dir_x[i], rays.ray.dir_y[i], rays.ray.dir_z[i]);
        const float c = 0.15f + 0.85f * std::abs(glm::dot(n, d));
        image.rgba[std::size_t(y) * width + x] = glm::vec4(c, c, c, 1);
      }
    }
    hits += rowHits;
  });
  return hits;
}

void runStage(const EmbreeStageArgs& a) {
  const auto [width, height] = parseImageSize("--size", a.request.size);
  if (!(a.request.radius > 0)) throw InputError("--radius: a positive sphere radius in world units");
  const Camera camera = loadCamera(a.cameraFile);
  // The particles, as Embree's sphere points want them: x, y, z, radius.
  const auto readStart = Clock::now();
  std::vector<glm::vec4> spheres;
  {
    auto source = openParticleFile(a.particles, ReadOptions{.velocity = false});
    ParticleChunk chunk;
    while (source->read(chunk, 1 << 20))
      for (const glm::vec3& p : chunk.positions)
        if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) spheres.emplace_back(p, a.request.radius);
  }
  const double read = secondsSince(readStart);
  EmbreeMemory memory;
  const auto start = Clock::now();
  RTCDevice device = rtcNewDevice(nullptr);
  if (!device)
    throw InputError("Embree: rtcNewDevice failed (error " + std::to_string(rtcGetDeviceError(nullptr)) + ")");
  rtcSetDeviceMemoryMonitorFunction(device, &EmbreeMemory::monitor, &memory);
  RTCScene scene = rtcNewScene(device);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_LOW);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
  rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, spheres.data(), 0,
                             sizeof(glm::vec4), spheres.size());
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene);
  const double build = secondsSince(start);
  if (rtcGetDeviceError(device) != RTC_ERROR_NONE) throw InputError("Embree: the scene did not build");
  RenderImage image;
  image.width = width;
  image.height = height;
  image.rgba.assign(std::size_t(width) * height, glm::vec4(0));
  const std::uint64_t hits = traceFrame(scene, camera, width, height, image);
  const double first = secondsSince(start);
  if (!a.image.empty()) writeImage(a.image, image);
  // Warm frames, turned as the frame stage turns flipscope's; each shades its image, as
  // flipscope's frames do.
  nlohmann::json warm = nlohmann::json::array();
  for (int i = 1; i <= a.request.orbitFrames; ++i) {
    const auto t = Clock::now();
    traceFrame(scene, orbitAbout(camera, camera.up, kOrbitStepDegrees * i), width, height, image);
    warm.push_back(secondsSince(t) * 1e3);
  }
  const std::int64_t embreePeak = memory.peak;
  rtcReleaseScene(scene);
  rtcReleaseDevice(device);
  char version[64];
  std::snprintf(version, sizeof version, "Embree %d.%d.%d", RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH);
  const nlohmann::json j{{"version", version},
                         {"particles", spheres.size()},
                         {"read_s", read},
                         {"build_s", build},
                         {"first_frame_s", first},
                         {"warm_frame_ms", warm},
                         {"hits", hits},
                         {"embree_bytes", std::max<std::int64_t>(embreePeak, 0)},
                         {"peak_rss_bytes", peakResidentBytes()}};
  writeTextAtomically(a.statsFile, j.dump(2) + "\n");
}

#else

void runStage(const EmbreeStageArgs&) {
  throw InputError("this flipscope was built without Embree (install libembree-dev and build again)");
}

#endif

}  // namespace

bool embreeAvailable() { return FLIPSCOPE_HAVE_EMBREE; }

double EmbreeStageResult::warmMeanMs() const { return meanOf(warmFrameMs); }

EmbreeStageResult runEmbreeStage(const EmbreeStageRequest& request, const fs::path& work) {
  const fs::path stats = work / "embree.json", log = work / "embree.log";
  char radius[32];
  std::snprintf(radius, sizeof radius, "%.9g", double(request.radius));
  runFlipscopeStage(
      "Embree stage",
      {"bench", "embree-stage", request.particles.string(), "--radius", radius, "--camera-file",
       request.cameraFile.string(), "--size", request.size, "--orbit-frames", std::to_string(request.orbitFrames),
       "--stats-file", stats.string(), "--image", (work / "embree.png").string()},
      log);
  std::ifstream in(stats);
  const nlohmann::json j = nlohmann::json::parse(in);
  EmbreeStageResult r;
  r.version = j["version"].get<std::string>();
  r.particles = j["particles"].get<std::uint64_t>();
  r.readSeconds = j["read_s"].get<double>();
  r.buildSeconds = j["build_s"].get<double>();
  r.firstFrameSeconds = j["first_frame_s"].get<double>();
  r.warmFrameMs = j["warm_frame_ms"].get<std::vector<double>>();
  r.hits = j["hits"].get<std::uint64_t>();
  r.embreeBytes = j["embree_bytes"].get<std::uint64_t>();
  r.peakBytes = j["peak_rss_bytes"].get<std::uint64_t>();
  return r;
}

void addBenchEmbreeStageCommand(CLI::App& bench) {
  auto args = std::make_shared<EmbreeStageArgs>();
  auto* cmd = bench.add_subcommand("embree-stage", "(internal) the same particles through Embree's sphere points");
  cmd->group("");  // run by bench render --peer embree, not listed
  cmd->add_option("particles", args->particles)->required();
  cmd->add_option("--radius", args->request.radius)->required();
  cmd->add_option("--camera-file", args->cameraFile)->required();
  cmd->add_option("--stats-file", args->statsFile)->required();
  cmd->add_option("--image", args->image);
  cmd->add_option("--size", args->request.size);
  cmd->add_option("--orbit-frames", args->request.orbitFrames);
  cmd->callback([args] { runStage(*args); });
}

}  // namespace flipscope::tools
