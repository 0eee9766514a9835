#include "pipeline/FramePipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>

#include <glm/trigonometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/Elapsed.h"
#include "core/Error.h"
#include "pipeline/GBufferPasses.h"
#include "raycast/CpuRaycaster.h"
#include "raycast/RaycastTypes.h"
#include "smoothing/CpuScreenDevice.h"
#include "smoothing/GpuScreenDevice.h"
#include "smoothing/SurfaceNormals.h"
#include "smoothing/detail/CpuScreenKernel.h"

namespace flipscope {

namespace {
using Clock = std::chrono::steady_clock;
}  // namespace

namespace glsl {
struct ProgressiveKernel : CpuScreenKernel {
#include "pipeline/glsl/Progressive.glsl"
};
}  // namespace glsl

namespace {
const ScreenPass kProgressiveDisplay{
    "Progressive.comp", "progressiveDisplay",
    cpuScreenPass<glsl::ProgressiveKernel, &glsl::ProgressiveKernel::progressiveDisplay>};
constexpr std::uint32_t kVec4PerHit = sizeof(RayHit) / sizeof(glm::vec4);
}  // namespace

EnvironmentMap loadEnvironmentMap(const std::filesystem::path& path) {
  ExrContents exr = readExr(path);
  EnvironmentMap map;
  map.width = exr.image.width;
  map.height = exr.image.height;
  map.texels = std::move(exr.image.rgba);
  for (glm::vec4& t : map.texels) {
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(t[c]) || t[c] < 0) t[c] = 0;
    t.a = 1;
  }
  return map;
}

/// The images and stage objects, created once the screen device exists.
struct FramePipeline::Stages {
  // Only the images the look's stages write exist (kNoImage otherwise): each is a frame of
  // memory, and on the CPU its first touch is most of a cold frame's screen time.
  static constexpr ScreenImage kNoImage = ~ScreenImage(0);
  ScreenImage hits = 0;               ///< kVec4PerHit vec4 per pixel: the ray-caster's, adopted
  ScreenImage rawGbuffer = kNoImage;  ///< depth, mask, thickness, attribute; with the thickness only
  ScreenImage gbuffer = 0;            ///< the same with the thickness blurred
  ScreenImage sphereNormals = 0;
  ScreenImage smoothed = kNoImage;  ///< the filter's output, when it changes the depth; see smoothedDepth()
  ScreenImage normals = kNoImage;   ///< reconstructed from the smoothed depth; not for lit spheres
  ScreenImage shaded = 0;
  ScreenImage display = kNoImage;  ///< progressive: what the viewer shows; see makeDisplayImages()
  ScreenImage shown = kNoImage;    ///< progressive: what it showed before
  std::unique_ptr<SurfaceFilter> filter;
  std::unique_ptr<SurfaceShading> shading;
  bool thickness = false;         ///< the ray-caster traces the thickness (liquid shading)
  bool litSpheres = false;        ///< spheres shading: the image's normals are the spheres'
  bool shadedReadOut = false;     ///< CPU: `shaded`'s pixels moved to the output since shade()
  std::vector<glm::vec4> downloaded[4];  ///< GPU: the images readOutput() reads back, kept
  /// The smoothed depth: the G-buffer itself when the filter keeps the depth (not run).
  ScreenImage smoothedDepth() const { return filter->keepsDepth() ? gbuffer : smoothed; }
  /// The image's normals: the spheres' for lit spheres, else those of the smoothed surface.
  ScreenImage imageNormals() const { return litSpheres ? sphereNormals : normals; }
};

FramePipeline::FramePipeline(BrickStore store, DeviceChoice device, const RenderSettings& settings,
                             const SurfaceSettings& surface, std::string* fallbackReason)
    : FramePipeline(std::make_shared<StoreBrickSource>(std::move(store), settings.attributes), device, settings,
                    surface, fallbackReason) {}

float thicknessSaturationCells(const ShadingOptions& shading) {
  // §3.6: the trace behind a hit goes on until the least absorbed channel keeps 1% (ln 100).
  const float weakest = std::min({shading.absorption.x, shading.absorption.y, shading.absorption.z});
  return weakest > 0 ? std::min(4.6051702f / weakest, float(kThicknessMaxCells)) : float(kThicknessMaxCells);
}

FramePipeline::FramePipeline(std::shared_ptr<BrickSource> source, DeviceChoice device, const RenderSettings& settings,
                             const SurfaceSettings& surface, std::string* fallbackReason)
    : mSurface(surface) {
  init(std::move(source), [&] { return createRaycastDevice(device, fallbackReason); }, settings);
}

FramePipeline::FramePipeline(std::shared_ptr<BrickSource> source, std::unique_ptr<RaycastDevice> raycaster,
                             const RenderSettings& settings, const SurfaceSettings& surface)
    : mSurface(surface) {
  FLIPSCOPE_CHECK(raycaster, "FramePipeline without a ray-caster");
  init(std::move(source), [&] { return std::move(raycaster); }, settings);
}

void FramePipeline::init(std::shared_ptr<BrickSource> source,
                         const std::function<std::unique_ptr<RaycastDevice>()>& makeRaycaster,
                         const RenderSettings& requested) {
  const SurfaceSettings surface = mSurface;
  RenderSettings settings = requested;
  // Only the liquid shading shows the thickness (§3.6); the other modes skip its trace.
  settings.thicknessSaturationCells =
      surface.shading.mode == ShadingMode::Liquid ? thicknessSaturationCells(surface.shading) : 0.0f;
  validate(settings);
  mSurface.smoothing = resolve(surface.smoothing);
  mSurface.shading.foam = settings.foam.mode == FoamMode::Volume;
  if (surface.shading.colorByAttribute && source->header().attribute == AttributeKind::None)
    throw InputError(source->name() +
                     ": the store has no per-particle attribute to colour by (convert with --attribute)");
  FLIPSCOPE_CHECK(!surface.shading.colorByAttribute || source->carriesAttributes(),
                  "colour by the attribute of a source that leaves it out (RenderSettings::attributes)");
  if (surface.shading.colorRange && !(surface.shading.colorRange->x < surface.shading.colorRange->y))
    throw InputError("--color-range: A must be less than B");
  const EnvironmentMap map = surface.environment.empty() ? EnvironmentMap{} : loadEnvironmentMap(surface.environment);
  auto raycaster = makeRaycaster();
  auto* gpu = dynamic_cast<GpuRaycaster*>(raycaster.get());
  const std::string name = raycaster->name();
  mRenderer = std::make_unique<FrameRenderer>(std::move(source), std::move(raycaster), settings);
  if (gpu)
    mScreen = std::make_unique<GpuScreenDevice>(name);
  else
    mScreen = std::make_unique<CpuScreenDevice>();
  ScreenFrame frame{};
  frame.width = settings.width;
  frame.height = settings.height;
  mScreen->setFrame(frame);
  mStages = std::make_unique<Stages>();
  Stages& s = *mStages;
  s.thickness = settings.thicknessSaturationCells > 0.0f;
  s.litSpheres = mSurface.shading.mode == ShadingMode::Spheres;
  if (auto* gpuScreen = dynamic_cast<GpuScreenDevice*>(mScreen.get())) {
    s.hits = gpuScreen->adoptFrameBuffer(&gpu->hitBuffer(), kVec4PerHit);
  } else {
    auto& cpu = static_cast<CpuRaycaster&>(mRenderer->device());
    s.hits = static_cast<CpuScreenDevice&>(*mScreen).adoptFramePixels(
        [&cpu] {
          const std::span<const RayHit> hits = cpu.hits();
          return std::span<const glm::vec4>(reinterpret_cast<const glm::vec4*>(hits.data()), hits.size() * kVec4PerHit);
        },
        kVec4PerHit);
  }
  s.filter = createSurfaceFilter(mSurface.smoothing);
  const bool smoothing = !s.filter->keepsDepth();
  const std::vector<ScreenImage> images =
      mScreen->createFrameImages(3 + std::size_t(s.thickness) + std::size_t(smoothing) + std::size_t(!s.litSpheres));
  auto next = images.begin();
  if (s.thickness) s.rawGbuffer = *next++;
  s.gbuffer = *next++;
  s.sphereNormals = *next++;
  if (smoothing) s.smoothed = *next++;
  if (!s.litSpheres) s.normals = *next++;
  s.shaded = *next++;
  s.shading = std::make_unique<SurfaceShading>(*mScreen, mSurface.shading, map);
}

FramePipeline::~FramePipeline() = default;

std::string FramePipeline::deviceName() const { return mRenderer->device().name(); }

ScreenFrame FramePipeline::screenFrame(const Camera& camera) const {
  const RenderSettings& settings = mRenderer->settings();
  const StoreHeader& header = mRenderer->source().header();
  const double tanHalf = std::tan(glm::radians(camera.fovYDegrees) * 0.5);
  ScreenFrame f{};
  f.forward = glm::vec4(glm::vec3(camera.forward()), 0.0f);
  f.right = glm::vec4(glm::vec3(camera.right()), 0.0f);
  f.up = glm::vec4(glm::vec3(camera.trueUp()), 0.0f);
  f.worldUp = glm::vec4(glm::vec3(glm::normalize(mSurface.up)), 0.0f);
  f.width = settings.width;
  f.height = settings.height;
  f.tanHalfFovY = float(tanHalf);
  f.aspect = float(settings.width) / float(settings.height);
  f.focalPixels = float(settings.height / (2.0 * tanHalf));
  f.particleRadius = float(settings.radius * header.cellSize);
  f.cellSize = float(header.cellSize);
  return f;
}

const FrameOutput& FramePipeline::render(int frame, const Camera& camera, int direction) {
  const auto start = Clock::now();
  mFrame = frame;
  mCamera = camera;
  StageTimes stages;
  const RenderStats stats = mRenderer->trace(frame, camera, direction);
  stages.trace = msSince(start);
  shade(frame, camera, stages);
  const auto readStart = Clock::now();
  FrameOutput& out = mOutput;
  readOutput();
  stages.readback = msSince(readStart);
  out.stats = stats;
  out.stages = stages;
  out.stages.total = msSince(start);
  return out;
}

void FramePipeline::begin(int frame, const Camera& camera, int direction) {
  makeDisplayImages();
  mRenderer->begin(frame, camera, direction);
  mFrame = frame;
  mCamera = camera;
}

FramePipeline::Progress FramePipeline::advance(double budgetMs) {
  const auto start = Clock::now();
  Progress progress;
  progress.stats = mRenderer->advance(budgetMs, &progress.changed);
  progress.stages.trace = msSince(start);
  if (progress.changed) {
    shade(mFrame, mCamera, progress.stages);
    Stages& s = *mStages;
    mScreen->run(kProgressiveDisplay, nullptr, 0, {s.hits, s.shaded, s.shown}, s.display);
    mScreen->copy(s.display, s.shown);
    mScreen->finish();
  }
  progress.stages.total = msSince(start);
  return progress;
}

void FramePipeline::makeDisplayImages() {
  Stages& s = *mStages;
  if (s.display != Stages::kNoImage) return;
  const std::vector<ScreenImage> images = mScreen->createFrameImages(2);
  s.display = images[0];
  s.shown = images[1];
  mScreen->clear(s.display);
  mScreen->clear(s.shown);
}

std::vector<glm::vec4> FramePipeline::downloadDisplay() {
  makeDisplayImages();
  return mScreen->download(mStages->display);
}

const gl::Buffer* FramePipeline::displayBuffer() {
  auto* gpu = dynamic_cast<GpuScreenDevice*>(mScreen.get());
  if (!gpu) return nullptr;
  makeDisplayImages();
  return &gpu->buffer(mStages->display);
}

void FramePipeline::shade(int frame, const Camera& camera, StageTimes& stages) {
  Stages& s = *mStages;
  ScreenDevice& device = *mScreen;
  auto timed = [&](double& ms, auto&& work) {
    const auto begin = Clock::now();
    work();
    device.finish();
    ms = msSince(begin);
  };
  device.setFrame(screenFrame(camera));
  timed(stages.gbuffer, [&] {
    device.runPair(kGBufferHits, nullptr, 0, {s.hits}, s.thickness ? s.rawGbuffer : s.gbuffer, s.sphereNormals);
    if (s.thickness) device.run(kBlurThickness, nullptr, 0, {s.rawGbuffer}, s.gbuffer);
  });
  if (!s.filter->keepsDepth()) timed(stages.smoothing, [&] { s.filter->apply(device, s.gbuffer, s.smoothed); });
  // The spheres shading lights the sphere normals; the surface's are not reconstructed.
  if (!s.litSpheres) timed(stages.normals, [&] { reconstructNormals(device, s.smoothedDepth(), s.normals); });
  // The attribute values of the G-buffer's 0 and 1: the frame's quantization range.
  const FrameStats stats =
      mRenderer->source().carriesAttributes() ? mRenderer->source().frame(frame)->stats : FrameStats{};
  s.shading->setFrameAttributeRange(stats.attributeMin, stats.attributeMax);
  timed(stages.shading, [&] { s.shading->shade(device, s.gbuffer, s.imageNormals(), s.sphereNormals, s.shaded); });
  s.shadedReadOut = false;
}

const FrameOutput& FramePipeline::readOutput() {
  Stages& s = *mStages;
  ScreenDevice& device = *mScreen;
  FrameOutput& out = mOutput;
  out.frame = mFrame;
  out.stats = {};
  out.stages = {};
  const StoreHeader& header = mRenderer->source().header();
  const bool attribute = mRenderer->source().carriesAttributes();
  const FrameStats stats = attribute ? mRenderer->source().frame(mFrame)->stats : FrameStats{};
  RenderImage& image = out.image;
  image.width = device.width();
  image.height = device.height();
  // The CPU device's images are read in place, its shaded pixels moved into the output (once a
  // shading: the next one writes the image the output gave back); the GPU's are downloaded.
  auto* cpu = dynamic_cast<CpuScreenDevice*>(&device);
  if (cpu) {
    if (!s.shadedReadOut) cpu->exchangePixels(s.shaded, image.rgba);
    s.shadedReadOut = true;
  } else {
    device.downloadInto(s.shaded, image.rgba);
  }
  if (mOutputLayers == OutputLayers::Colour) {  // the layers' storage freed, not kept
    for (auto* layer : {&image.depth, &image.unsmoothedDepth, &image.thickness, &image.attribute})
      std::vector<float>().swap(*layer);
    std::vector<glm::vec3>().swap(image.normal);
    std::vector<glm::vec4>().swap(image.foam);
    image.attributeName.clear();
    return out;
  }
  auto read = [&](ScreenImage handle, int slot) -> std::span<const glm::vec4> {
    if (cpu) return cpu->pixels(handle);
    device.downloadInto(handle, s.downloaded[slot]);
    return s.downloaded[slot];
  };
  const auto gbuffer = read(s.gbuffer, 0);
  const auto smoothed = read(s.smoothedDepth(), 1);
  const auto normals = read(s.imageNormals(), 2);
  const std::size_t n = gbuffer.size();
  constexpr float kInf = std::numeric_limits<float>::infinity();
  image.depth.resize(n);
  image.unsmoothedDepth.resize(n);
  image.thickness.resize(s.thickness ? n : 0);
  image.normal.resize(n);
  image.foam.clear();
  image.attribute.clear();
  image.attributeName.clear();
  if (mSurface.shading.foam) {
    const auto hitExtras = s.litSpheres ? normals : read(s.sphereNormals, 3);
    image.foam.resize(n);
    for (std::size_t i = 0; i < n; ++i) image.foam[i] = glm::vec4(mSurface.shading.foamColour * hitExtras[i].w, hitExtras[i].w);
  }
  if (attribute) {
    image.attribute.resize(n);
    image.attributeName = header.attributeName;
  }
  const float span = stats.attributeMax - stats.attributeMin;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<std::size_t>& rows) {
    for (std::size_t i = rows.begin(); i != rows.end(); ++i) {
      const bool hit = gbuffer[i].y > 0.5f;
      image.depth[i] = hit ? smoothed[i].x : kInf;
      image.unsmoothedDepth[i] = hit ? gbuffer[i].x : kInf;
      if (s.thickness) image.thickness[i] = hit ? gbuffer[i].z : 0.0f;
      image.normal[i] = hit ? glm::vec3(normals[i]) : glm::vec3(0);
      if (attribute) image.attribute[i] = hit ? stats.attributeMin + gbuffer[i].w * span : 0.0f;
    }
  });
  return out;
}

}  // namespace flipscope
