// `flipscope bench render --peer embree` on a small frame: flipscope and Embree render the same
// particles with the same camera, each stage in a child of its own, and the JSON reports both.
// Embree draws what flipscope draws: their first images cover nearly the same pixels.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include <png.h>

#include "TestSupport.h"
#include "pipeline/ImageWriter.h"

namespace {

/// Pixels of Embree's PNG at `path` where a sphere was hit (alpha above one half: the stage draws
/// nothing elsewhere).
std::vector<bool> covered(const std::filesystem::path& path, std::uint32_t& width, std::uint32_t& height) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  EXPECT_TRUE(png_image_begin_read_from_file(&image, path.c_str())) << path;
  image.format = PNG_FORMAT_RGBA;
  std::vector<png_byte> pixels(PNG_IMAGE_SIZE(image));
  EXPECT_TRUE(png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr)) << path;
  width = image.width;
  height = image.height;
  std::vector<bool> out(std::size_t(width) * height);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = pixels[4 * i + 3] > 127;
  return out;
}

TEST(BenchRenderPeer, EmbreeAndFlipscopeRenderTheSameParticlesWithTheSameCamera) {
  flipscope::testing::TempDir dir("bench-peer");
  const flipscope::testing::CommandRun run = flipscope::testing::runFlipscope(
      "bench render --particles 200k --sizes 96x54 --orbit-frames 2 --no-vdb-tool --device cpu --peer embree "
      "--peer-runs 2 --json "
      "--work-dir '" +
      dir.path().string() + "'");
  ASSERT_EQ(run.exitCode, 0) << run.output;
  const auto j = nlohmann::json::parse(run.output);
  ASSERT_TRUE(j.contains("peer")) << run.output;
  const auto& peer = j["peer"];
  EXPECT_EQ(peer["size"], "96x54");
  EXPECT_GT(peer["radius_world"].get<double>(), 0.0);
  EXPECT_GT(peer["flipscope_convert_s"].get<double>(), 0.0);
  EXPECT_NEAR(peer["flipscope_convert_and_first_image_s"].get<double>(),
              peer["flipscope_convert_s"].get<double>() + peer["flipscope_first_image_s"].get<double>(), 1e-9);
  EXPECT_GT(peer["flipscope_render_peak_rss_bytes"].get<double>(), 0.0);
  // The same convert with the particle spacing given, and its store's first image.
  EXPECT_GT(peer["flipscope_spacing_given_convert_s"].get<double>(), 0.0);
  EXPECT_GT(peer["flipscope_spacing_given_first_image_s"].get<double>(), 0.0);
  EXPECT_NEAR(peer["flipscope_spacing_given_convert_and_first_image_s"].get<double>(),
              peer["flipscope_spacing_given_convert_s"].get<double>() +
                  peer["flipscope_spacing_given_first_image_s"].get<double>(),
              1e-9);
  EXPECT_FALSE(std::filesystem::exists(dir / "peer_spacing_given.store")) << "removed after its image";
  // Each run in turn, the last (whose images the work directory holds) also as "peer".
  ASSERT_TRUE(j.contains("peer_runs") && j.contains("peer_summary")) << run.output;
  ASSERT_EQ(j.at("peer_runs").size(), 2u) << run.output;
  EXPECT_EQ(j.at("peer_runs").at(1), peer);
  if (peer["embree"].is_null()) {  // built without Embree (it is optional)
    ASSERT_EQ(std::getenv("FLIPSCOPE_REQUIRE_EMBREE"), nullptr) << "CI installs libembree-dev: " << run.output;
    GTEST_SKIP() << "this flipscope is built without Embree (Debian: libembree-dev)";
  }
  const auto& embree = peer["embree"];
  std::uint32_t w = 0, h = 0;
  // The summary's medians, ranges and counts are of the runs' own numbers.
  const auto& summary = j.at("peer_summary");
  ASSERT_EQ(summary.at("runs"), 2) << run.output;
  for (const char* target : {"warm_frame_x_embree", "first_image_x_sooner", "spacing_given_first_image_x_sooner"}) {
    const auto& t = summary.at(target);
    std::vector<double> ratios;
    for (std::size_t r = 0; r < 2; ++r) {
      const auto& p = j.at("peer_runs").at(r);
      const double embreeFirst = p.at("embree").at("build_and_first_frame_s").get<double>();
      ratios.push_back(std::string(target) == "warm_frame_x_embree"
                           ? p.at("flipscope_warm_frame_ms").get<double>() /
                                 p.at("embree").at("warm_frame_ms").get<double>()
                       : std::string(target) == "first_image_x_sooner"
                           ? embreeFirst / p.at("flipscope_convert_and_first_image_s").get<double>()
                           : embreeFirst / p.at("flipscope_spacing_given_convert_and_first_image_s").get<double>());
      EXPECT_NEAR(t.at("per_run").at(r).get<double>(), ratios.back(), 1e-9 * ratios.back()) << target << " run " << r;
    }
    std::sort(ratios.begin(), ratios.end());
    EXPECT_NEAR(t.at("median").get<double>(), 0.5 * (ratios[0] + ratios[1]), 1e-9 * ratios[1]) << target;
    EXPECT_DOUBLE_EQ(t.at("min").get<double>(), ratios[0]) << target;
    EXPECT_DOUBLE_EQ(t.at("max").get<double>(), ratios[1]) << target;
    const bool warm = std::string(target) == "warm_frame_x_embree";
    EXPECT_EQ(t.at("met_runs").get<int>(),
              std::count_if(ratios.begin(), ratios.end(), [warm](double x) { return warm ? x <= 1.0 : x >= 10.0; }))
        << target;
  }
  EXPECT_EQ(embree["version"].get<std::string>().rfind("Embree 3.", 0), 0u);
  EXPECT_GE(embree["build_and_first_frame_s"].get<double>(), embree["build_s"].get<double>());
  EXPECT_GT(embree["read_s"].get<double>(), 0.0);
  EXPECT_GT(embree["warm_frame_ms"].get<double>(), 0.0);
  EXPECT_GT(embree["embree_bytes"].get<double>(), 0.0);

  // Same particles, camera and radius: the silhouettes agree but for the rim (flipscope's
  // spheres sit at jittered cell positions, Embree's at the particles).
  const auto a = covered(dir / "embree.png", w, h);
  const flipscope::RenderImage ours = flipscope::readExr(dir / "peer_flipscope.exr").image;
  std::vector<bool> b(ours.depth.size());
  for (std::size_t i = 0; i < b.size(); ++i) b[i] = std::isfinite(ours.depth[i]);
  ASSERT_EQ(w, 96u);
  ASSERT_EQ(h, 54u);
  ASSERT_EQ(ours.width, w);
  ASSERT_EQ(ours.height, h);
  std::size_t both = 0, either = 0;
  for (std::size_t i = 0; i < a.size(); ++i) both += a[i] && b[i], either += a[i] || b[i];
  EXPECT_EQ(std::size_t(embree["hits"].get<std::uint64_t>()),
            std::size_t(std::count(a.begin(), a.end(), true)));
  ASSERT_GT(either, 96u * 54u / 20) << "the particles are in view";
  EXPECT_GT(double(both) / double(either), 0.85) << both << " of " << either << " pixels covered by both";
}

}  // namespace
