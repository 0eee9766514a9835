#include "tools/RenderJob.h"

#include <cstdio>

#include "core/Error.h"
#include "core/ProcessMemory.h"
#include "core/Progress.h"
#include "pipeline/ImageWriter.h"

namespace flipscope::tools {

std::string outputPathForFrame(const std::string& pattern, int frame) {
  std::string out;
  for (std::size_t i = 0; i < pattern.size();) {
    if (pattern[i] != '#') {
      out += pattern[i++];
      continue;
    }
    std::size_t run = 0;
    while (i + run < pattern.size() && pattern[i + run] == '#') ++run;
    std::string digits = std::to_string(std::abs(frame));
    if (digits.size() < run) digits.insert(0, run - digits.size(), '0');
    out += (frame < 0 ? "-" : "") + digits;
    i += run;
  }
  return out;
}

void checkOutputPattern(const std::string& output, FrameRange frames) {
  if (!isImagePath(output)) throw InputError("-o: '" + output + "' must end in .exr or .png");
  if (frames.last > frames.first && output.find('#') == std::string::npos)
    throw InputError("-o: rendering frames " + std::to_string(frames.first) + "-" + std::to_string(frames.last) +
                     " needs '#' in the output name (e.g. out_####.exr)");
}

std::vector<RenderedFile> runRenderJob(const RenderJob& job) {
  keepHeapForReuse();  // core/ProcessMemory.h
  BrickStore store = BrickStore::open(job.store);
  const std::vector<int> stored = store.frames();
  if (stored.empty())
    throw FileError(job.store, "the store has no complete frame (an interrupted convert? convert again)");
  const int first = job.firstFrame.value_or(stored.front());
  const int last = job.lastFrame.value_or(first);
  if (last < first) throw InputError("--frames: the last frame comes before the first");
  for (int f = first; f <= last; ++f)
    if (!store.hasFrame(f))
      throw InputError(job.store + ": the store has no frame " + std::to_string(f) + " (it has " +
                       std::to_string(stored.front()) + "-" + std::to_string(stored.back()) + ")");
  checkOutputPattern(job.output, {first, last});

  RenderRequest request = job;
  const bool layers = keepsImageLayers(job.output);
  request.attributeOutput = layers;  // a PNG's look may need none
  const auto [settings, surface] = resolve(request, store);
  const StoreHeader& header = store.header();
  std::string fallback;
  FramePipeline pipeline(store, job.device, settings, surface, &fallback);
  pipeline.setOutputLayers(layers ? OutputLayers::All : OutputLayers::Colour);
  FrameRenderer& renderer = pipeline.renderer();
  if (!job.quiet) {
    if (!fallback.empty()) std::fprintf(stderr, "render: using the CPU ray-caster: %s\n", fallback.c_str());
    const SmoothingOptions& smoothing = resolve(surface.smoothing);
    std::printf("render: %s; sphere radius %.3g cells%s; smoothing %s (%d iterations, strength %g)\n",
                pipeline.deviceName().c_str(), settings.radius,
                job.radius                              ? ""
                : store.header().particleSpacing > 0 ? " (1.5 particle spacings of the store)"
                                                     : " (the store records no particle spacing)",
                smoothing.name.c_str(), smoothing.iterations, smoothing.strength);
    if (settings.foam.mode == FoamMode::Keep)
      std::printf("render: foam kept as spheres\n");
    else
      std::printf("render: foam %s, from %s (threshold %g)\n", foamModeName(settings.foam.mode),
                  foamSourceName(settings.foam.source), settings.foam.threshold);
    if (surface.shading.colorByAttribute) {
      const char* map = colorMapName(surface.shading.colorMap);
      if (surface.shading.colorRange)
        std::printf("render: colour by %s through %s, %g to %g\n", header.attributeName.c_str(), map,
                    surface.shading.colorRange->x, surface.shading.colorRange->y);
      else
        std::printf("render: colour by %s through %s, over each frame's range\n", header.attributeName.c_str(), map);
    }
  }

  Camera camera;
  if (job.camera) {
    camera = *job.camera;
  } else {
    std::uint64_t leftOut = 0;
    camera = defaultRenderCamera(renderer.source(), first, last, settings.width, settings.height, surface.up, &leftOut);
    if (leftOut > 0 && !job.quiet) std::printf("render: %s\n", framingNote(leftOut, last > first).c_str());
  }
  if (!job.saveCamera.empty()) saveCamera(job.saveCamera, camera);

  std::vector<RenderedFile> files;
  for (int f = first; f <= last; ++f) {
    const FrameOutput& result = pipeline.render(f, camera, last > first ? 1 : 0);
    const std::string path = outputPathForFrame(job.output, f);
    writeImage(path, result.image);
    const RenderStats& s = result.stats;
    const StageTimes& t = result.stages;
    if (!job.quiet) {
      std::printf(
          "  frame %d: %ux%u, %d %s%s; bricks: %llu requested, %llu uploaded, %zu resident (pool %sB), "
          "%zu in the frame; %.0f ms (trace %.0f, stream %.0f, upload %.0f; g-buffer %.0f, smoothing %.0f, "
          "normals %.0f, shading %.0f, read-back %.0f) -> %s\n",
          f, result.image.width, result.image.height, s.passes, s.passes == 1 ? "pass" : "passes",
          s.converged ? "" : " (pass limit: not converged)", (unsigned long long)s.bricksRequested,
          (unsigned long long)s.bricksUploaded, s.bricksResident, Progress::humanCount(double(s.poolBytes)).c_str(),
          s.frameBricks, t.total, s.traceMs, s.streamMs, s.uploadMs, t.gbuffer, t.smoothing, t.normals, t.shading,
          t.readback, path.c_str());
      std::fflush(stdout);
    }
    files.push_back({f, path, s, t});
  }
  return files;
}

}  // namespace flipscope::tools
