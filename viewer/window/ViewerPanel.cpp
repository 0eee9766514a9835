// The viewer's Dear ImGui panel: timeline, look (filter and its parameters, foam, radius,
// jitter, colour by attribute, render scale) and live statistics with the plots of Reichl et
// al. 2014 Fig. 13 (frame times and bricks uploaded per frame over the last seconds).
#include <imgui.h>

#include <algorithm>
#include <string>

#include "smoothing/SurfaceFilter.h"
#include "viewer/window/ViewerApp.h"

namespace flipscope::viewer {

void ViewerApp::drawPanel() {
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(330, 0), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.8f);
  ImGui::Begin("flipscope");
  if (!mConversionStatus.empty()) ImGui::TextWrapped("%s", mConversionStatus.c_str());
  if (!mTimeline || !mPipeline) {
    ImGui::Text("waiting for the first frame...");
    ImGui::End();
    return;
  }

  // Timeline.
  const std::vector<int>& frames = mTimeline->frames();
  int index = int(mTimeline->index());
  if (ImGui::SliderInt("frame", &index, 0, int(frames.size()) - 1, std::to_string(mTimeline->frame()).c_str()))
    mTimeline->seek(frames[std::size_t(index)]);
  if (ImGui::Button(mTimeline->playing() ? "pause" : "play")) mTimeline->togglePlaying();
  ImGui::SameLine();
  bool loop = mTimeline->loop();
  if (ImGui::Checkbox("loop", &loop)) mTimeline->setLoop(loop);
  ImGui::SameLine();
  bool reverse = mTimeline->reverse();
  if (ImGui::Checkbox("reverse", &reverse)) mTimeline->setReverse(reverse);
  float speed = float(mTimeline->speed());
  if (ImGui::SliderFloat("fps", &speed, 1.0f, 60.0f, "%.0f")) mTimeline->setSpeed(speed);

  // Look: any change rebuilds the pipeline (buildPipeline).
  if (ImGui::CollapsingHeader("look", ImGuiTreeNodeFlags_DefaultOpen)) {
    const auto& filters = surfaceFilters();
    if (ImGui::BeginCombo("smoothing", mLook.filter.c_str())) {
      for (const SurfaceFilterInfo& f : filters)
        if (ImGui::Selectable(std::string(f.name).c_str(), f.name == mLook.filter)) {
          mLook.filter = std::string(f.name);
          mLook.iterations = -1;
          mLook.strength = -1.0f;
        }
      ImGui::EndCombo();
    }
    const SmoothingOptions resolved = resolve(SmoothingOptions{mLook.filter, mLook.iterations, mLook.strength});
    const auto info = std::find_if(filters.begin(), filters.end(), [&](const auto& f) { return f.name == mLook.filter; });
    // Inputs take effect on Enter or the +/- buttons: every change rebuilds the pipeline.
    int iterations = resolved.iterations;
    if (ImGui::InputInt("iterations", &iterations, 5, 25, ImGuiInputTextFlags_EnterReturnsTrue))
      mLook.iterations = std::max(0, iterations);
    float strength = resolved.strength;
    if (info != filters.end() && info->maxStrength > info->minStrength &&
        ImGui::InputFloat("strength", &strength, 0.5f, 2.0f, "%.2f", ImGuiInputTextFlags_EnterReturnsTrue))
      mLook.strength = std::clamp(strength, info->minStrength, info->maxStrength);
    int foam = mLook.foam == FoamMode::Volume ? 0 : mLook.foam == FoamMode::Remove ? 1 : 2;
    if (ImGui::Combo("foam", &foam, "volume\0remove\0keep\0"))
      mLook.foam = foam == 0 ? FoamMode::Volume : foam == 1 ? FoamMode::Remove : FoamMode::Keep;
    float radius = mLook.radius;
    if (ImGui::InputFloat("radius (cells)", &radius, 0.25f, 1.0f, "%.2f", ImGuiInputTextFlags_EnterReturnsTrue))
      mLook.radius = std::clamp(radius, 0.5f, float(kMaxOverlap) - 0.5f - (mLook.jitter ? 0.25f : 0.0f));
    ImGui::Checkbox("jitter", &mLook.jitter);
    if (mSource->header().attribute != AttributeKind::None)
      ImGui::Checkbox(("colour by " + mSource->header().attributeName).c_str(), &mLook.colorByAttribute);
    float scale = mLook.scale;
    if (mOptions.screenshot.empty() &&
        ImGui::InputFloat("render scale", &scale, 0.125f, 0.25f, "%.3f", ImGuiInputTextFlags_EnterReturnsTrue))
      mLook.scale = std::clamp(scale, 0.125f, 1.0f);
  }

  // Live statistics.
  if (ImGui::CollapsingHeader("stats", ImGuiTreeNodeFlags_DefaultOpen)) {
    const RenderStats& s = mProgress.stats;
    const auto samples = mHistory.frameMs();
    ImGui::Text("%s", mDeviceName.c_str());
    ImGui::Text("%ux%u  %.1f fps  ui frame %.1f ms", mBuiltSize.x, mBuiltSize.y, mHistory.fps(),
                samples.empty() ? 0.0 : double(samples.back()));
    ImGui::Text("frame %d: %s in %d passes (%.0f ms)", mBegunFrame,
                mPipeline->finished() ? (s.converged ? "converged" : "pass limit") : "refining", s.passes,
                mPipeline->finished() ? mConvergeMs : 0.0);
    ImGui::Text("trace %.1f  smooth %.1f  normals %.1f  shade %.1f ms", mLastStages.trace, mLastStages.smoothing,
                mLastStages.normals, mLastStages.shading);
    ImGui::Text("stream %.1f  upload %.1f  foam %.1f ms (frame so far)", s.streamMs, s.uploadMs, s.foamMs);
    ImGui::Text("bricks: %zu resident, %llu requested, %llu uploaded, %zu in frame", s.bricksResident,
                (unsigned long long)s.bricksRequested, (unsigned long long)s.bricksUploaded, s.frameBricks);
    const ConvertedBrickCache& cache = mPipeline->renderer().streamer().cache();
    ImGui::Text("CPU cache %.1f / %.0f MB, %zu frames cached", double(cache.bytes()) / 1e6, double(cache.budget()) / 1e6,
                mFramesCached);
    ImGui::Text("GPU pool %.1f MB", double(s.poolBytes) / 1e6);
    ImGui::PlotLines("frame ms", samples.data(), int(samples.size()), 0, nullptr, 0.0f, FLT_MAX, ImVec2(0, 50));
    const auto bricks = mHistory.bricksUploaded();
    ImGui::PlotHistogram("uploads", bricks.data(), int(bricks.size()), 0, nullptr, 0.0f, FLT_MAX, ImVec2(0, 50));
  }
  ImGui::TextWrapped("drag: orbit (shift/right: pan), wheel: zoom, tab: fly (WASD QE), F frame, R reset, "
                     "space play, arrows step, S screenshot, C camera%s",
                     mFlyMode ? "  [fly]" : "");
  if (!mMessage.empty()) ImGui::TextWrapped("%s", mMessage.c_str());
  ImGui::End();
}

}  // namespace flipscope::viewer
