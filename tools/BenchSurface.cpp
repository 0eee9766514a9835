// `flipscope bench surface`: the screen-space stages of a frame (Reichl et al. 2014 §3.4, §3.6)
// for every surface filter, on the devices at hand, and how well each filter recovers a known
// surface.
//
// Time: smoothing (per filter), normal reconstruction and shading, each ended by
// ScreenDevice::finish(), on the CPU reference (CpuScreenDevice) and on OpenGL (GpuScreenDevice
// in a headless EGL context; skipped with the reason when none can be created). One warm-up,
// then the median of --repeats runs. The input is the G-buffer of the scene below, exactly as
// FramePipeline builds it from the ray-caster's hits.
//
// Quality: a sphere of radius R in front of a rectangle of the plane z = planeZ (both facing the
// camera, seen obliquely), sampled by uniformly random points on both surfaces, one particle per
// cell^2 of surface, binned by the real preprocess (convertFrame) into a store in --work-dir and
// rendered through FramePipeline with each --smoothing filter (sphere radius: the default for a
// store whose particle spacing is one cell; the shaded images go to --work-dir too). Per pixel,
// the camera ray (Camera::pixelRay) is intersected with the analytic surface offset towards the
// camera by the sphere radius r (a sphere of radius R + r and the plane moved by r: the envelope
// of spheres centred on the surface). Measured pixels: the ray meets the offset surface, no pixel within 3 px (a 7x7
// window) meets a different surface or none (no analytic depth discontinuity near it), and the
// pipeline's image has a hit there. Over them:
//   normal error: angle in degrees between FrameOutput's image.normal (the normals reconstructed
//     from the smoothed depth) and the analytic normal; mean and 95th percentile;
//   depth error: mean |d - d*| / cell size, d the smoothed linear camera depth (image.depth), d*
//     the linear camera depth of the offset surface; bias: the mean of (d - d*) / cell size
//     (positive: behind the envelope, where the bumps between sphere tops lie).
// `none` is the unsmoothed sphere depth: the baseline.
//
// Paper: Reichl et al. 2014 Fig. 10, GTX Titan at 1280x720: bilateral 15 ms, ROF (75 iterations)
// 13 ms for the smoothing stage.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <nlohmann/json.hpp>

#include "core/Elapsed.h"
#include "core/Error.h"
#include "core/Progress.h"
#include "gl/EglContext.h"
#include "pipeline/FramePipeline.h"
#include "preprocess/Convert.h"
#include "preprocess/particles/PointSpanSource.h"
#include "raycast/RaycastTypes.h"
#include "smoothing/CpuScreenDevice.h"
#include "smoothing/GpuScreenDevice.h"
#include "smoothing/SurfaceNormals.h"
#include "smoothing/SurfaceShading.h"
#include "tools/BenchFoam.h"
#include "tools/BenchStatistics.h"
#include "tools/CliValues.h"
#include "tools/Commands.h"
#include "tools/JsonOutput.h"

namespace flipscope::tools {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using Json = nlohmann::ordered_json;

constexpr double kCellSize = 0.01;    // world units (not 1, so that a unit slip shows)
constexpr int kSilhouettePixels = 3;  // measured pixels lie this far from an analytic depth discontinuity
// Reichl et al. 2014 Fig. 10: smoothing at 1280x720 on a GTX Titan.
constexpr double kPaperBilateralMs = 15.0;
constexpr double kPaperRofMs = 13.0;
constexpr double kPaperFoamMsPerBrick = 0.15;  // Table 2, 64^3 bricks
constexpr int kPaperRofIterations = 75;

struct BenchSurfaceArgs {
  std::string size = "1280x720";
  int repeats = 5;
  std::string device = "both";
  std::string particles = "300k";
  std::string workDir;
  bool json = false;
};


/// A sphere in front of a rectangle of the plane z = planeZ, in world units; sized so that
/// `particles` points make one particle per cell^2 of surface.
struct AnalyticScene {
  // In units of the sphere radius: the plane's half extents and the gap between the sphere and it.
  static constexpr double kPlaneHalfX = 6.0, kPlaneHalfY = 4.0, kGap = 0.6;

  double radius = 0;  ///< R, world units
  glm::dvec3 centre{0};
  double planeZ = 0;
  glm::dvec2 planeMin{0}, planeMax{0};
  std::uint64_t sphereParticles = 0, planeParticles = 0;
  Box domain;

  explicit AnalyticScene(std::uint64_t particles) {
    const double sphereArea = 4.0 * std::numbers::pi, planeArea = 4.0 * kPlaneHalfX * kPlaneHalfY;  // per R^2
    const double radiusCells = std::sqrt(double(particles) / (sphereArea + planeArea));
    radius = radiusCells * kCellSize;
    sphereParticles = std::uint64_t(std::llround(double(particles) * sphereArea / (sphereArea + planeArea)));
    planeParticles = particles - sphereParticles;
    const double margin = 8 * kCellSize;
    // The plane on a layer of cell centres; the domain starts at the origin.
    planeZ = (std::floor(margin / kCellSize) + 0.5) * kCellSize;
    centre = {kPlaneHalfX * radius + margin, kPlaneHalfY * radius + margin, planeZ + (1.0 + kGap) * radius};
    planeMin = glm::dvec2(centre) - glm::dvec2(kPlaneHalfX, kPlaneHalfY) * radius;
    planeMax = glm::dvec2(centre) + glm::dvec2(kPlaneHalfX, kPlaneHalfY) * radius;
    domain = Box{{0, 0, 0}, {2 * centre.x, 2 * centre.y, centre.z + radius + margin}};
  }

  std::vector<glm::vec3> sample(std::uint64_t seed) const {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<glm::vec3> points;
    points.reserve(sphereParticles + planeParticles);
    for (std::uint64_t i = 0; i < sphereParticles; ++i) {
      const double z = 2 * unit(rng) - 1, phi = 2 * std::numbers::pi * unit(rng),
                   s = std::sqrt(std::max(0.0, 1 - z * z));
      points.push_back(glm::vec3(centre + radius * glm::dvec3(s * std::cos(phi), s * std::sin(phi), z)));
    }
    for (std::uint64_t i = 0; i < planeParticles; ++i)
      points.push_back(
          glm::vec3(glm::mix(planeMin.x, planeMax.x, unit(rng)), glm::mix(planeMin.y, planeMax.y, unit(rng)), planeZ));
    return points;
  }

  /// Obliquely from the front, right and above; the sphere fills about 60% of the image height.
  Camera camera() const {
    Camera c;
    c.target = centre;
    c.eye = centre + 4.8 * radius * glm::normalize(glm::dvec3(0.4, 0.3, 1.0));
    c.up = {0, 1, 0};
    c.fovYDegrees = 40;
    return c;
  }

  enum Surface { kNone = 0, kSphere = 1, kPlane = 2 };
  struct Hit {
    Surface surface = kNone;
    double t = 0;
    glm::dvec3 normal{0};
  };
  /// The first intersection of the ray with the surface offset by `offset` towards the camera.
  Hit intersect(const glm::dvec3& eye, const glm::dvec3& dir, double offset) const {
    Hit hit;
    const glm::dvec3 oc = eye - centre;
    const double b = glm::dot(oc, dir), r = radius + offset;
    const double disc = b * b - (glm::dot(oc, oc) - r * r);
    if (disc >= 0) {
      const double t = -b - std::sqrt(disc);
      if (t > 0) return {kSphere, t, glm::normalize(eye + t * dir - centre)};
    }
    if (dir.z != 0) {
      const double t = (planeZ + offset - eye.z) / dir.z;
      const glm::dvec3 p = eye + t * dir;
      if (t > 0 && p.x >= planeMin.x && p.x <= planeMax.x && p.y >= planeMin.y && p.y <= planeMax.y)
        hit = {kPlane, t, {0, 0, 1}};
    }
    return hit;
  }
};

/// The analytic image: per pixel the surface met, its linear camera depth and normal, and
/// whether the pixel is measured (kSilhouettePixels from any change of surface).
struct AnalyticImage {
  std::vector<AnalyticScene::Surface> surface;
  std::vector<float> depth;
  std::vector<glm::dvec3> normal;
  std::vector<bool> measured;
  std::size_t hits = 0, measuredCount = 0;
};

AnalyticImage analyticImage(const AnalyticScene& scene, const Camera& camera, double offset, std::uint32_t width,
                            std::uint32_t height) {
  const std::size_t n = std::size_t(width) * height;
  AnalyticImage a;
  a.surface.assign(n, AnalyticScene::kNone);
  a.depth.assign(n, std::numeric_limits<float>::infinity());
  a.normal.assign(n, glm::dvec3(0));
  a.measured.assign(n, false);
  const glm::dvec3 forward = camera.forward();
  for (std::uint32_t y = 0; y < height; ++y)
    for (std::uint32_t x = 0; x < width; ++x) {
      const glm::dvec3 dir = camera.pixelRay(x, y, width, height);
      const AnalyticScene::Hit hit = scene.intersect(camera.eye, dir, offset);
      const std::size_t i = std::size_t(y) * width + x;
      a.surface[i] = hit.surface;
      if (hit.surface == AnalyticScene::kNone) continue;
      a.depth[i] = float(hit.t * glm::dot(dir, forward));
      a.normal[i] = hit.normal;
      ++a.hits;
    }
  const int r = kSilhouettePixels;
  for (int y = 0; y < int(height); ++y)
    for (int x = 0; x < int(width); ++x) {
      const std::size_t i = std::size_t(y) * width + std::size_t(x);
      if (a.surface[i] == AnalyticScene::kNone) continue;
      bool same = true;
      for (int dy = -r; dy <= r && same; ++dy)
        for (int dx = -r; dx <= r && same; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= int(width) || qy >= int(height)) continue;
          same = a.surface[std::size_t(qy) * width + std::size_t(qx)] == a.surface[i];
        }
      a.measured[i] = same;
      a.measuredCount += same;
    }
  return a;
}

struct Quality {
  double normalMeanDeg = 0, normalP95Deg = 0;
  double sphereNormalMeanDeg = 0, planeNormalMeanDeg = 0;
  double depthErrorCells = 0, depthBiasCells = 0;
  std::size_t pixels = 0;  ///< measured pixels the image has a hit at
};

Quality measure(const RenderImage& image, const AnalyticImage& a, double cellSize) {
  Quality q;
  std::vector<double> angles;
  double sphereSum = 0, planeSum = 0, absSum = 0, signedSum = 0;
  std::size_t spherePixels = 0, planePixels = 0;
  for (std::size_t i = 0; i < a.measured.size(); ++i) {
    if (!a.measured[i] || !std::isfinite(image.depth[i]) || glm::length(image.normal[i]) < 0.5f) continue;
    const double cosine = std::clamp(glm::dot(glm::normalize(glm::dvec3(image.normal[i])), a.normal[i]), -1.0, 1.0);
    const double angle = glm::degrees(std::acos(cosine));
    angles.push_back(angle);
    (a.surface[i] == AnalyticScene::kSphere ? sphereSum : planeSum) += angle;
    ++(a.surface[i] == AnalyticScene::kSphere ? spherePixels : planePixels);
    const double error = (double(image.depth[i]) - double(a.depth[i])) / cellSize;
    absSum += std::abs(error);
    signedSum += error;
  }
  q.pixels = angles.size();
  if (angles.empty()) return q;
  double sum = 0;
  for (double angle : angles) sum += angle;
  q.normalMeanDeg = sum / double(angles.size());
  const std::size_t k = std::size_t(0.95 * double(angles.size() - 1));
  std::nth_element(angles.begin(), angles.begin() + std::ptrdiff_t(k), angles.end());
  q.normalP95Deg = angles[k];
  q.sphereNormalMeanDeg = spherePixels ? sphereSum / double(spherePixels) : 0;
  q.planeNormalMeanDeg = planePixels ? planeSum / double(planePixels) : 0;
  q.depthErrorCells = absSum / double(angles.size());
  q.depthBiasCells = signedSum / double(angles.size());
  return q;
}

/// FramePipeline's G-buffer (depth, mask, blurred thickness, attribute) and sphere normals,
/// rebuilt from the ray-caster's hits and the image's (blurred) thickness.
struct GBuffer {
  std::vector<glm::vec4> surface, sphereNormals;
};

GBuffer gbufferOf(const std::vector<RayHit>& hits, const RenderImage& image) {
  GBuffer g;
  g.surface.assign(hits.size(), glm::vec4(0));
  g.sphereNormals.assign(hits.size(), glm::vec4(0));
  for (std::size_t i = 0; i < hits.size(); ++i) {
    const RayHit& hit = hits[i];
    if (hit.status != kRayHit) continue;
    g.surface[i] = glm::vec4(hit.depth, 1.0f, image.thickness[i], hit.normal.w);
    g.sphereNormals[i] = glm::vec4(glm::vec3(hit.normal), 1.0f);
  }
  return g;
}

struct StageMs {
  double smoothing = 0, normals = 0, shading = 0;
};

/// Median stage times of every filter on `device` (after one warm-up run each).
std::map<std::string, StageMs> timeStages(ScreenDevice& device, const ScreenFrame& frame, const GBuffer& gbuffer,
                                          int repeats, bool quiet) {
  device.setFrame(frame);
  const ScreenImage surface = device.createFrameImage(), sphereNormals = device.createFrameImage();
  const ScreenImage smoothed = device.createFrameImage(), normals = device.createFrameImage();
  const ScreenImage shaded = device.createFrameImage();
  device.upload(surface, gbuffer.surface);
  device.upload(sphereNormals, gbuffer.sphereNormals);
  SurfaceShading shading(device, ShadingOptions{}, EnvironmentMap{});
  device.finish();

  std::map<std::string, StageMs> result;
  for (const SurfaceFilterInfo& info : surfaceFilters()) {
    if (!quiet)
      std::fprintf(stderr, "bench surface: timing %s on %s ...\n", std::string(info.name).c_str(),
                   device.name().c_str());
    auto filter = createSurfaceFilter(SmoothingOptions{.name = std::string(info.name)});
    auto timed = [&](auto&& work) {
      const auto start = Clock::now();
      work();
      device.finish();
      return msSince(start);
    };
    std::vector<double> smoothing, normal, shade;
    for (int run = 0; run <= repeats; ++run) {  // run 0 warms up
      const double s = timed([&] { filter->apply(device, surface, smoothed); });
      const double n = timed([&] { reconstructNormals(device, smoothed, normals); });
      const double h = timed([&] { shading.shade(device, surface, normals, sphereNormals, shaded); });
      if (run == 0) continue;
      smoothing.push_back(s);
      normal.push_back(n);
      shade.push_back(h);
    }
    result[std::string(info.name)] = {median(smoothing), median(normal), median(shade)};
  }
  return result;
}

struct DeviceResult {
  std::string key;   ///< "cpu" or "gl"
  std::string name;  ///< the device's own
  std::map<std::string, StageMs> stages;
};

bool isSoftware(const std::string& renderer) {
  return renderer.find("llvmpipe") != std::string::npos || renderer.find("softpipe") != std::string::npos;
}

void runBenchSurface(const BenchSurfaceArgs& a) {
  const auto [width, height] = parseImageSize("--size", a.size);
  const std::uint64_t particles = parseCount("--particles", a.particles);
  if (particles < 1000) throw InputError("--particles: at least 1000 for a sphere and a plane, got " + a.particles);
  const fs::path work = a.workDir.empty() ? fs::temp_directory_path() / "flipscope-bench-surface" : fs::path(a.workDir);
  fs::create_directories(work);
  const fs::path storeDir = work / "store";
  const bool quiet = a.json;

  // The scene, binned by the real preprocess.
  const AnalyticScene scene(particles);
  {
    if (!quiet)
      std::fprintf(stderr, "bench surface: %s particles on a sphere and a plane -> %s ...\n",
                   Progress::humanCount(double(particles)).c_str(), storeDir.c_str());
    ConvertOptions options;
    options.domain = scene.domain;
    options.cellSize = kCellSize;
    options.particleSpacing = kCellSize;  // one particle per cell^2 of surface: one cell apart
    options.progress = Progress::Mode::Silent;
    fs::remove_all(storeDir);
    BrickStore store = BrickStore::createOrAppend(storeDir, makeStoreHeader(*options.domain, options));
    const std::vector<glm::vec3> points = scene.sample(20140609);
    PointSpanSource source(points, "bench surface scene");
    convertFrame(source, store, 0, options);
  }

  // Which devices time the stages.
  const bool wantCpu = a.device == "cpu" || a.device == "both" || a.device == "auto";
  const bool wantGl = a.device == "gpu" || a.device == "both" || a.device == "auto";
  gl::EglContext context;
  std::string glSkipped;
  if (wantGl) {
    try {
      context = gl::EglContext::create();
      if (a.device == "auto" && isSoftware(context.renderer())) {
        glSkipped = "--device auto: the OpenGL renderer is software (" + context.renderer() + ")";
        context = gl::EglContext();
      }
    } catch (const gl::Unavailable& e) {
      if (a.device == "gpu") throw CommandFailed(std::string("bench surface: --device gpu: ") + e.what());
      glSkipped = std::string("no OpenGL 4.5 context through EGL: ") + e.what();
    }
  }
  const bool useCpu = wantCpu && (a.device != "auto" || !context.isValid());
  const std::string glName = context.isValid() ? "OpenGL (" + context.platform() + "): " + context.renderer() : "";
  // The EGL context is made again by a GPU pipeline; release it while the pipelines render.
  context = gl::EglContext();

  // Quality: through FramePipeline, one per filter (on the CPU reference when it is measured).
  RenderSettings settings;
  settings.width = width;
  settings.height = height;
  const StoreHeader header = BrickStore::open(storeDir).header();
  settings.radius = defaultSphereRadius(header, settings.jitter);
  // One particle per cell^2 of surface is sparse enough for the foam classification (§3.5) to
  // take much of it for foam and leave holes; the filters are measured on the whole surface.
  settings.foam.mode = FoamMode::Keep;
  const double sphereRadiusWorld = double(settings.radius) * header.cellSize;
  const Camera camera = scene.camera();
  const AnalyticImage analytic = analyticImage(scene, camera, sphereRadiusWorld, width, height);
  const DeviceChoice qualityDevice = useCpu ? DeviceChoice::Cpu : DeviceChoice::Gpu;
  std::string qualityName;
  std::map<std::string, Quality> quality;
  std::map<std::string, SmoothingOptions> resolved;
  GBuffer gbuffer;
  ScreenFrame frame{};
  for (const SurfaceFilterInfo& info : surfaceFilters()) {
    const std::string name(info.name);
    if (!quiet) std::fprintf(stderr, "bench surface: rendering with --smoothing %s ...\n", name.c_str());
    SurfaceSettings surface;
    surface.smoothing.name = name;
    resolved[name] = resolve(surface.smoothing);
    FramePipeline pipeline(BrickStore::open(storeDir), qualityDevice, settings, surface);
    const FrameOutput& out = pipeline.render(0, camera);
    quality[name] = measure(out.image, analytic, header.cellSize);
    writeImage(work / ("surface_" + name + ".png"), out.image);
    if (qualityName.empty()) {
      qualityName = pipeline.deviceName();
      frame = pipeline.screenFrame(camera);
      gbuffer = gbufferOf(pipeline.renderer().device().readHits(), out.image);
    }
  }

  // Time: the stages on each device, from the same G-buffer.
  std::vector<DeviceResult> devices;
  if (useCpu) {
    CpuScreenDevice cpu;
    devices.push_back({"cpu", cpu.name(), timeStages(cpu, frame, gbuffer, a.repeats, quiet)});
  }
  if (!glName.empty()) {
    context = gl::EglContext::create();
    {
      GpuScreenDevice gpu(glName);
      devices.push_back({"gl", gpu.name(), timeStages(gpu, frame, gbuffer, a.repeats, quiet)});
    }  // destroyed while its context is current
    context = gl::EglContext();
  }

  // Foam classification (§3.5) of every brick the view uploads, on each device.
  std::vector<FoamClassifyTiming> foam;
  if (useCpu) foam.push_back(timeFoamClassification(storeDir, DeviceChoice::Cpu, settings, camera, a.repeats));
  if (!glName.empty()) foam.push_back(timeFoamClassification(storeDir, DeviceChoice::Gpu, settings, camera, a.repeats));

  // The fastest device's ROF.
  double rofMs = 0;
  std::string rofDevice;
  for (const DeviceResult& d : devices) {
    const double ms = d.stages.at("rof").smoothing;
    if (rofDevice.empty() || ms < rofMs) rofMs = ms, rofDevice = d.key;
  }
  const bool paperSize = width == 1280 && height == 720;
  const double coverage = double(analytic.measuredCount) / double(std::size_t(width) * height);

  if (a.json) {
    Json j;
    j["width"] = width;
    j["height"] = height;
    j["repeats"] = a.repeats;
    j["particles"] = particles;
    j["scene"] = {{"sphere_radius_cells", scene.radius / kCellSize},
                  {"sphere_particles", scene.sphereParticles},
                  {"plane_particles", scene.planeParticles},
                  {"cell_size", kCellSize},
                  {"particle_radius_cells", settings.radius},
                  {"jitter_cells", settings.jitter},
                  {"analytic_pixels", analytic.hits},
                  {"measured_pixels", analytic.measuredCount},
                  {"silhouette_margin_px", kSilhouettePixels}};
    j["devices"] = Json::object();
    for (const DeviceResult& d : devices) j["devices"][d.key] = d.name;
    j["gl_skipped"] = glSkipped.empty() ? Json(nullptr) : Json(glSkipped);
    j["quality_device"] = qualityName;
    j["rof_ms"] = rofMs;
    j["rof_device"] = rofDevice;
    j["filters"] = Json::object();
    for (const SurfaceFilterInfo& info : surfaceFilters()) {
      const std::string name(info.name);
      const Quality& q = quality.at(name);
      Json f{{"iterations", resolved[name].iterations},
             {"strength", resolved[name].strength},
             {"normal_error_deg", q.normalMeanDeg},
             {"normal_error_p95_deg", q.normalP95Deg},
             {"sphere_normal_error_deg", q.sphereNormalMeanDeg},
             {"plane_normal_error_deg", q.planeNormalMeanDeg},
             {"depth_error_cells", q.depthErrorCells},
             {"depth_bias_cells", q.depthBiasCells},
             {"pixels", q.pixels}};
      for (const DeviceResult& d : devices) {
        const StageMs& s = d.stages.at(name);
        f[d.key] = {{"smoothing_ms", s.smoothing}, {"normals_ms", s.normals}, {"shading_ms", s.shading}};
      }
      j["filters"][name] = f;
    }
    j["paper"] = {{"source", "Reichl et al. 2014 Fig. 10"},
                  {"gpu", "GTX Titan"},
                  {"width", 1280},
                  {"height", 720},
                  {"bilateral_ms", kPaperBilateralMs},
                  {"rof_ms", kPaperRofMs},
                  {"rof_iterations", kPaperRofIterations},
                  {"foam_classification_ms_per_brick", kPaperFoamMsPerBrick}};
    j["foam_classification"] = Json::array();
    for (const FoamClassifyTiming& f : foam)
      j["foam_classification"].push_back({{"device", f.device}, {"bricks", f.bricks}, {"ms_per_brick", f.msPerBrick}});
    printJson(j);
    return;
  }

  std::printf(
      "bench surface: %ux%u, a sphere (R = %.1f cells) before a plane, %s particles (%s on the sphere), "
      "1 per cell^2 of surface; particle radius %.2f cells, jitter %.2f\n",
      width, height, scene.radius / kCellSize, Progress::humanCount(double(particles)).c_str(),
      Progress::humanCount(double(scene.sphereParticles)).c_str(), settings.radius, settings.jitter);
  for (const DeviceResult& d : devices) std::printf("  %-3s = %s\n", d.key.c_str(), d.name.c_str());
  if (!glSkipped.empty()) std::printf("  gl skipped: %s\n", glSkipped.c_str());
  std::printf(
      "times: median of %d runs after one warm-up, ms; quality: %s pipeline over %zu pixels (%.0f%% of the "
      "image, >= %d px from silhouettes)\n\n",
      a.repeats, qualityName.c_str(), analytic.measuredCount, 100.0 * coverage, kSilhouettePixels);

  std::printf("%-15s %5s", "filter", "iters");
  for (const DeviceResult& d : devices) std::printf(" | %3s smooth %8s %8s", d.key.c_str(), "normals", "shading");
  std::printf(" | %-12s | %-15s %5s | %-10s %6s\n", "paper smooth", "normal err deg", "p95", "depth cells", "bias");
  for (const SurfaceFilterInfo& info : surfaceFilters()) {
    const std::string name(info.name);
    const Quality& q = quality.at(name);
    std::printf("%-15s %5d", (name == "none" ? std::string("none (base)") : name).c_str(), resolved[name].iterations);
    for (const DeviceResult& d : devices) {
      const StageMs& s = d.stages.at(name);
      std::printf(" | %10.1f %8.1f %8.1f", s.smoothing, s.normals, s.shading);
    }
    const double paper = name == "rof" ? kPaperRofMs : name == "bilateral" ? kPaperBilateralMs : 0;
    if (paper > 0)
      std::printf(" | %12.0f", paper);
    else
      std::printf(" | %12s", "-");
    std::printf(" | %15.2f %5.1f | %11.2f %+6.2f\n", q.normalMeanDeg, q.normalP95Deg, q.depthErrorCells,
                q.depthBiasCells);
  }
  std::printf(
      "\npaper (Reichl et al. 2014 Fig. 10, GTX Titan, 1280x720): bilateral %.0f ms, ROF %d iterations %.0f "
      "ms\n",
      kPaperBilateralMs, kPaperRofIterations, kPaperRofMs);
  if (!rofDevice.empty())
    std::printf("here: ROF %d iterations %.1f ms on %s at %ux%u (%.1fx the paper's time%s)\n",
                resolved["rof"].iterations, rofMs, rofDevice.c_str(), width, height, rofMs / kPaperRofMs,
                paperSize ? "" : "; not the paper's image size");
  std::printf(
      "normal error: angle to the analytic normal; depth error: |smoothed depth - analytic depth of the "
      "surface offset by the particle radius| in cells (bias: signed mean, + = behind)\n");
  std::printf("\nfoam classification (§3.5), radius %.2f cells, every brick of the view (%u^3 cells), median of %d:\n",
              settings.radius, header.brickSize, a.repeats);
  for (const FoamClassifyTiming& f : foam)
    std::printf("  %-60s %6llu bricks %9.3f ms per brick\n", f.device.c_str(), (unsigned long long)f.bricks,
                f.msPerBrick);
  std::printf("  %-60s %13s %9.2f ms per 64^3 brick\n", "paper (Table 2, GTX Titan)", "", kPaperFoamMsPerBrick);
  std::printf("store and images (surface_<filter>.png) in %s\n", work.c_str());
}

}  // namespace

void addBenchSurfaceCommand(CLI::App& bench) {
  auto args = std::make_shared<BenchSurfaceArgs>();
  auto* cmd = bench.add_subcommand(
      "surface",
      "Smoothing, normals and shading times per filter and device; each filter's error on an analytic scene");
  cmd->add_option("--size", args->size, "Image size WxH")->capture_default_str();
  cmd->add_option("--repeats", args->repeats, "Timed runs per stage (the median is reported), after one warm-up")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--device", args->device, "both (CPU reference and OpenGL), auto, cpu or gpu (OpenGL)")
      ->check(CLI::IsMember({"both", "auto", "cpu", "gpu"}))
      ->capture_default_str();
  cmd->add_option("--particles", args->particles, "Particles of the analytic scene (sets its size in cells)")
      ->capture_default_str();
  cmd->add_option("--work-dir", args->workDir, "Where the store goes (default: a temp directory)");
  cmd->add_flag("--json", args->json, "Machine-readable output");
  cmd->callback([args] { runBenchSurface(*args); });
}

}  // namespace flipscope::tools
