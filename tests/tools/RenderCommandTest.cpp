// flipscope render and demo end to end: PNG and EXR files, flipbook names, the camera options,
// and clear errors with exit codes 2 (bad options) and 3 (bad files).
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>

#include <glm/geometric.hpp>
#include "TestSupport.h"

#include "pipeline/ImageWriter.h"

namespace {

namespace fs = std::filesystem;
using flipscope::testing::CommandRun;
using flipscope::testing::runFlipscope;

/// Width and height from a PNG's IHDR chunk (bytes 16 to 23, big-endian), {0, 0} if not a PNG.
std::pair<std::uint32_t, std::uint32_t> pngSize(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  unsigned char header[24] = {};
  in.read(reinterpret_cast<char*>(header), sizeof header);
  if (!in || std::string(reinterpret_cast<char*>(header) + 1, 3) != "PNG") return {0, 0};
  auto be32 = [&](int at) {
    return std::uint32_t(header[at]) << 24 | std::uint32_t(header[at + 1]) << 16 | std::uint32_t(header[at + 2]) << 8 |
           header[at + 3];
  };
  return {be32(16), be32(20)};
}

class Render : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(runFlipscope("synth -o " + path("f_####.bin") + " --particles 30k --frames 0-1").exitCode, 0);
    CommandRun convert =
        runFlipscope("convert " + path("f_####.bin") + " -o " + path("store") + " --resolution 96 --brick-size 32 -q");
    ASSERT_EQ(convert.exitCode, 0) << convert.output;
  }
  std::string path(const std::string& name) const { return (dir / name).string(); }
  /// Renders the store at 64x36 on the CPU with `options` into `name` and reads it back.
  flipscope::ExrContents renderExr(const std::string& name, const std::string& options) {
    CommandRun r =
        runFlipscope("render " + path("store") + " -o " + path(name) + " --size 64x36 --device cpu " + options);
    EXPECT_EQ(r.exitCode, 0) << options << "\n" << r.output;
    return flipscope::readExr(path(name));
  }
  flipscope::testing::TempDir temp{"render"};
  const fs::path& dir = temp.path();
};

TEST_F(Render, WritesPngAndExrWithDepthAndNormals) {
  CommandRun png = runFlipscope("render " + path("store") + " -o " + path("a.png") + " --size 64x36 --device cpu");
  ASSERT_EQ(png.exitCode, 0) << png.output;
  EXPECT_EQ(pngSize(path("a.png")), std::make_pair(64u, 36u));

  CommandRun exr =
      runFlipscope("render " + path("store") + " -o " + path("a.exr") + " --size 64x36 --frame 1 --jitter off");
  ASSERT_EQ(exr.exitCode, 0) << exr.output;
  const flipscope::ExrContents contents = flipscope::readExr(path("a.exr"));
  for (const char* channel : {"R", "G", "B", "A", "Z", "N.X", "N.Y", "N.Z", "unsmoothed.Z", "thickness"})
    EXPECT_NE(std::find(contents.channels.begin(), contents.channels.end(), channel), contents.channels.end())
        << channel;
  std::size_t covered = 0;
  ASSERT_EQ(contents.image.foam.size(), contents.image.rgba.size()) << "the default foam is a volume";
  for (std::size_t i = 0; i < contents.image.rgba.size(); ++i) {
    EXPECT_EQ(contents.image.rgba[i].a, 1.0f) << "the environment fills the background";
    if (!std::isfinite(contents.image.depth[i])) {
      covered += contents.image.foam[i].a > 0.1f;  // foam, which has no depth
      continue;
    }
    ++covered;
    EXPECT_GT(contents.image.depth[i], 0.0f);
    EXPECT_NEAR(glm::length(contents.image.normal[i]), 1.0f, 1e-3f);
  }
  EXPECT_GT(covered, 64u * 36u / 10) << "the default camera frames the fluid and its foam";
}

TEST_F(Render, FlipbookAndCameraOptions) {
  CommandRun seq =
      runFlipscope("render " + path("store") + " -o " + path("seq_####.png") + " --frames 0-1 --size 32x18");
  ASSERT_EQ(seq.exitCode, 0) << seq.output;
  EXPECT_TRUE(fs::exists(path("seq_0000.png")));
  EXPECT_TRUE(fs::exists(path("seq_0001.png")));

  std::ofstream(path("cam.json")) << R"({"eye": [0.5, 0.4, 3.0], "target": [0.5, 0.2, 0.5], "fov": 35})";
  CommandRun file = runFlipscope("render " + path("store") + " -o " + path("cam.png") + " --size 32x18 --camera-file " +
                                 path("cam.json"));
  EXPECT_EQ(file.exitCode, 0) << file.output;
  CommandRun inline_ = runFlipscope("render " + path("store") + " -o " + path("cam2.png") +
                                    " --size 32x18 --camera 0.5,0.4,3,0.5,0.2,0.5,0,1,0,35");
  EXPECT_EQ(inline_.exitCode, 0) << inline_.output;
  CommandRun framed = runFlipscope("render " + path("store") + " -o " + path("framed.png") + " --size 32x18");
  EXPECT_EQ(framed.exitCode, 0) << framed.output;
  const auto bytes = [&](const std::string& name) {
    std::ifstream in(path(name), std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  EXPECT_EQ(bytes("cam.png"), bytes("cam2.png")) << "--camera-file and --camera give the same camera";
  EXPECT_NE(bytes("cam.png"), bytes("framed.png")) << "the camera options change the view";
  EXPECT_NE(bytes("seq_0000.png"), bytes("seq_0001.png")) << "a flipbook renders each frame";
}

// A real Houdini file (464 points of a Houdini 18.5 demo scene, .bgeo.sc) converts and renders
// with no options.
TEST_F(Render, AHoudiniFileRendersWithDefaults) {
  const fs::path houdini =
      fs::path(FLIPSCOPE_DATA_DIR) / "formats" / "houdini-bgeo-sc" / "delete_small_parts_demoscene.1.bgeo.sc";
  CommandRun convert = runFlipscope("convert '" + houdini.string() + "' -o " + path("houdini") + " -q");
  ASSERT_EQ(convert.exitCode, 0) << convert.output;
  CommandRun render =
      runFlipscope("render " + path("houdini") + " -o " + path("houdini.exr") + " --size 64x36 --device cpu");
  ASSERT_EQ(render.exitCode, 0) << render.output;
  const flipscope::RenderImage image = flipscope::readExr(path("houdini.exr")).image;
  std::size_t covered = 0;
  for (float depth : image.depth) covered += std::isfinite(depth);
  EXPECT_GT(covered, 64u * 36u / 20) << "the default camera frames the Houdini points";
}

// One particle flung ten thousand tank sizes away, converted with no options, lies in the store's
// domain: the default camera frames the tank without it, says so, and the tank fills the image.
TEST_F(Render, TheDefaultCameraLeavesOutAParticleFlungFarAway) {
  {
    std::ofstream ply(path("flung.ply"));
    const int n = 20;
    ply << "ply\nformat ascii 1.0\nelement vertex " << n * n * n + 1
        << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) ply << 0.05 * i << ' ' << 0.05 * j << ' ' << 0.05 * k << '\n';
    ply << "10000 0.5 0.5\n";
  }
  CommandRun convert = runFlipscope("convert " + path("flung.ply") + " -o " + path("flung"));
  ASSERT_EQ(convert.exitCode, 0) << convert.output;
  CommandRun render =
      runFlipscope("render " + path("flung") + " -o " + path("flung.exr") + " --size 64x36 --device cpu");
  ASSERT_EQ(render.exitCode, 0) << render.output;
  EXPECT_NE(render.output.find("leaves out 1 particle far from it"), std::string::npos) << render.output;
  const flipscope::RenderImage image = flipscope::readExr(path("flung.exr")).image;
  std::size_t covered = 0;
  for (float depth : image.depth) covered += std::isfinite(depth);
  EXPECT_GT(covered, 64u * 36u / 10) << "the default camera frames the tank, not the particle far away";
}

TEST_F(Render, SmoothingAndShadingOptionsChangeTheImage) {
  const auto render = [&](const std::string& name, const std::string& options) {
    return renderExr(name, options).image;
  };
  const auto none = render("none.exr", "--smoothing none");
  const auto rof = render("rof.exr", "--smoothing rof --smoothing-strength 8");
  const auto spheres = render("spheres.exr", "--shading spheres");
  double depthChange = 0, colourChange = 0;
  for (std::size_t i = 0; i < none.depth.size(); ++i) {
    if (std::isfinite(none.depth[i])) {
      EXPECT_EQ(none.depth[i], none.unsmoothedDepth[i]);
      depthChange = std::max(depthChange, double(std::abs(rof.depth[i] - none.depth[i])));
    }
    colourChange = std::max(colourChange, double(glm::length(glm::vec3(spheres.rgba[i] - rof.rgba[i]))));
  }
  EXPECT_GT(depthChange, 0.0);
  EXPECT_GT(colourChange, 0.05);
}

TEST_F(Render, FoamOptionsChangeTheImageAndTheExrHasAFoamLayer) {
  // The synth fluid's splash holds isolated particles: a high threshold makes many cells foam.
  const auto volume = renderExr("volume.exr", "--foam volume --foam-threshold 0.6");
  const auto removed = renderExr("remove.exr", "--foam remove --foam-threshold 0.6");
  const auto kept = renderExr("keep.exr", "--foam keep");
  EXPECT_NE(std::find(volume.channels.begin(), volume.channels.end(), "foam.A"), volume.channels.end());
  EXPECT_EQ(std::find(kept.channels.begin(), kept.channels.end(), "foam.A"), kept.channels.end());
  double foam = 0, colourChange = 0;
  std::size_t hitsKept = 0, hitsRemoved = 0;
  for (std::size_t i = 0; i < kept.image.depth.size(); ++i) {
    foam = std::max(foam, double(volume.image.foam[i].a));
    hitsKept += std::isfinite(kept.image.depth[i]);
    hitsRemoved += std::isfinite(removed.image.depth[i]);
    colourChange = std::max(colourChange, double(glm::length(glm::vec3(volume.image.rgba[i] - removed.image.rgba[i]))));
  }
  EXPECT_GT(foam, 0.05) << "some foam is visible";
  EXPECT_LT(hitsRemoved, hitsKept) << "removed foam leaves background where only foam was";
  EXPECT_GT(colourChange, 0.05) << "the volume is composited over the image";
}

// Particle files instead of a store: the frames rendered are converted with convert's defaults
// into a temporary store under $TMPDIR, gone afterwards, and the image is the one convert then
// render give. Temporary stores a killed render left are removed; a running one's (locked) are
// not, nor other users' entries, nor what a symlink points to.
TEST_F(Render, ParticleFilesRenderThroughATemporaryStore) {
  const fs::path tmp = dir / "tmp";
  const fs::path stale = tmp / "flipscope-render-999999999-Ab12Cd", running = tmp / "flipscope-render-1-Ef34Gh";
  fs::create_directories(stale);
  std::ofstream(stale / "store.fsh") << "left by a render killed";
  fs::create_directories(running);
  const int lock = ::open(running.c_str(), O_RDONLY | O_DIRECTORY);
  ASSERT_EQ(::flock(lock, LOCK_EX), 0);
  fs::create_directories(dir / "kept");
  std::ofstream(dir / "kept" / "file") << "not a temporary store";
  fs::create_symlink(dir / "kept", tmp / "flipscope-render-2-Ij56Kl");
  const bool root = ::geteuid() == 0;  // another user's entry can be made only as root
  const fs::path foreign = tmp / "flipscope-render-3-Mn78Op";
  if (root) {
    fs::create_directories(foreign);
    ASSERT_EQ(::chown(foreign.c_str(), 65534, 65534), 0);
  }
  const flipscope::testing::ScopedEnvironment environment("TMPDIR", tmp.string());
  const std::string size = " --size 64x36 --device cpu --jitter off";

  CommandRun direct = runFlipscope("render " + path("f_####.bin") + " --frame 1 -o " + path("direct.exr") + size);
  ASSERT_EQ(direct.exitCode, 0) << direct.output;
  EXPECT_NE(direct.output.find("converting frame 1 of the particle files into a temporary store"), std::string::npos)
      << direct.output;
  EXPECT_FALSE(fs::exists(stale)) << "the store of a render that is gone is removed";
  EXPECT_TRUE(fs::exists(running)) << "the store of a running render stays";
  EXPECT_TRUE(fs::exists(dir / "kept" / "file")) << "a symlink is not followed";
  if (root) {
    EXPECT_TRUE(fs::exists(foreign)) << "another user's entry stays";
    fs::remove(foreign);
  }
  ::close(lock);
  fs::remove_all(running);
  fs::remove(tmp / "flipscope-render-2-Ij56Kl");
  EXPECT_TRUE(fs::is_empty(tmp)) << "the temporary store is removed after the render";

  CommandRun convert = runFlipscope("convert " + path("f_####.bin") + " --frames 1 -o " + path("defaults") + " -q");
  ASSERT_EQ(convert.exitCode, 0) << convert.output;
  CommandRun stored = runFlipscope("render " + path("defaults") + " --frame 1 -o " + path("stored.exr") + size);
  ASSERT_EQ(stored.exitCode, 0) << stored.output;
  const flipscope::RenderImage a = flipscope::readExr(path("direct.exr")).image;
  const flipscope::RenderImage b = flipscope::readExr(path("stored.exr")).image;
  ASSERT_EQ(a.depth.size(), b.depth.size());
  std::size_t covered = 0, differ = 0;
  for (std::size_t i = 0; i < a.depth.size(); ++i) {
    covered += std::isfinite(a.depth[i]);
    differ +=
        !(a.depth[i] == b.depth[i] || (std::isinf(a.depth[i]) && std::isinf(b.depth[i]))) || a.rgba[i] != b.rgba[i];
  }
  EXPECT_GT(covered, 64u * 36u / 10);
  EXPECT_EQ(differ, 0u) << "the same image as convert, then render";

  // No --frame: the first frame found, whatever later frames lack (here f_0001's companion);
  // --frames: a flipbook of the frames converted together; a file without a pattern is the
  // frame --frame names.
  fs::copy_file(path("f_0000.bin"), path("g_0000.bin"));
  CommandRun first =
      runFlipscope("render " + path("f_####.bin") + " " + path("g_####.bin") + " -o " + path("first.png") + size);
  ASSERT_EQ(first.exitCode, 0) << first.output;
  EXPECT_NE(first.output.find("converting frame 0 "), std::string::npos) << first.output;
  EXPECT_EQ(pngSize(path("first.png")), std::make_pair(64u, 36u));
  CommandRun book = runFlipscope("render " + path("f_####.bin") + " --frames 0-1 -o " + path("book_####.png") + size);
  ASSERT_EQ(book.exitCode, 0) << book.output;
  EXPECT_NE(book.output.find("converting frames 0-1 "), std::string::npos) << book.output;
  EXPECT_TRUE(fs::exists(path("book_0000.png")) && fs::exists(path("book_0001.png")));
  CommandRun plainFrame = runFlipscope("render " + path("f_0001.bin") + " --frame 5 -o " + path("five_#.png") + size);
  ASSERT_EQ(plainFrame.exitCode, 0) << plainFrame.output;
  EXPECT_NE(plainFrame.output.find("frame 5:"), std::string::npos) << plainFrame.output;
  EXPECT_TRUE(fs::exists(path("five_5.png")));
  EXPECT_TRUE(fs::is_empty(tmp));

  // Bad inputs: the file or the option named, exit 3 or 2, no image and no store left; the
  // output and the inputs are checked before anything is made.
  {
    std::ofstream bad(path("bad.ply"));
    bad << "ply\nformat binary_little_endian 1.0\nelement vertex 1000\nproperty float x\nproperty float y\n"
           "property float z\nend_header\n0123456789";
  }
  CommandRun damaged = runFlipscope("render " + path("bad.ply") + " -o " + path("bad.png") + size);
  EXPECT_EQ(damaged.exitCode, 3) << damaged.output;
  EXPECT_NE(damaged.output.find("bad.ply"), std::string::npos) << damaged.output;
  CommandRun plain = runFlipscope("render " + path("f_0000.bin") + " --frames 0-1 -o " + path("p_####.png") + size);
  EXPECT_EQ(plain.exitCode, 2) << plain.output;
  EXPECT_NE(plain.output.find("no frame pattern"), std::string::npos) << plain.output;
  CommandRun missing =
      runFlipscope("render " + path("f_####.bin") + " " + path("g_####.bin") + " --frame 1 -o " + path("m.png") + size);
  EXPECT_EQ(missing.exitCode, 3) << missing.output;
  EXPECT_NE(missing.output.find("g_0001.bin"), std::string::npos) << missing.output;
  CommandRun output = runFlipscope("render " + path("f_####.bin") + " --frames 0-1 -o " + path("p.png") + size);
  EXPECT_EQ(output.exitCode, 2) << output.output;
  for (const CommandRun* run : {&plain, &missing, &output})
    EXPECT_EQ(run->output.find("converting"), std::string::npos) << run->output;
  {
    const flipscope::testing::ScopedEnvironment nowhere("TMPDIR", path("bad.ply"));  // a file, not a directory
    CommandRun noTemporary = runFlipscope("render " + path("f_####.bin") + " -o " + path("t.png") + size);
    EXPECT_EQ(noTemporary.exitCode, 4) << noTemporary.output;
    EXPECT_NE(noTemporary.output.find("set TMPDIR"), std::string::npos) << noTemporary.output;
  }
  EXPECT_FALSE(fs::exists(path("bad.png")) || fs::exists(path("p_0000.png")) || fs::exists(path("p.png")) ||
               fs::exists(path("m.png")) || fs::exists(path("t.png")));
  EXPECT_TRUE(fs::is_empty(tmp));

  // SIGTERM while converting (the convert's test hook, Convert.h) removes the store, and so does
  // one after it, before the render; between two frames, the frame already listed stays, and
  // the next render removes it.
  for (const char* stop : {"brick:1:TERM", "render-store:1:TERM"}) {
    const flipscope::testing::ScopedEnvironment stopAt("FLIPSCOPE_CONVERT_STOP", stop);
    CommandRun stopped = runFlipscope("render " + path("f_####.bin") + " -o " + path("s.png") + size);
    EXPECT_EQ(stopped.exitCode, 128 + SIGTERM) << stop << "\n" << stopped.output;
    EXPECT_TRUE(fs::is_empty(tmp)) << stop;
  }
  {
    const flipscope::testing::ScopedEnvironment stopAt("FLIPSCOPE_CONVERT_STOP", "frame:1:TERM");
    CommandRun stopped = runFlipscope("render " + path("f_####.bin") + " --frames 0-1 -o " + path("s_####.png") + size);
    EXPECT_EQ(stopped.exitCode, 128 + SIGTERM) << stopped.output;
  }
  EXPECT_FALSE(fs::is_empty(tmp));
  ASSERT_EQ(runFlipscope("render " + path("f_####.bin") + " -o " + path("s.png") + size).exitCode, 0);
  EXPECT_TRUE(fs::is_empty(tmp));
  EXPECT_FALSE(fs::exists(path("s_0000.png")));
}

TEST_F(Render, BadInputsGiveClearErrors) {
  // Exit code 2: a bad option or value; 3: an unreadable or damaged file.
  const auto expectError = [&](const std::string& args, const std::string& needle, int code = 2) {
    CommandRun r = runFlipscope("render " + args);
    EXPECT_EQ(r.exitCode, code) << args << "\n" << r.output;
    EXPECT_NE(r.output.find(needle), std::string::npos) << args << "\n" << r.output;
  };
  expectError(path("store") + " -o " + path("x.png") + " --frame 7", "no frame 7");
  expectError(path("store") + " -o " + path("x.tif"), "must end in .exr or .png");
  expectError(path("store") + " -o " + path("x.png") + " --frames 0-1", "'#'");
  expectError(path("store") + " -o " + path("x.png") + " --camera 1,2,3", "expected 10 numbers");
  expectError(path("store") + " -o " + path("x.png") + " --camera 0,0,0,0,0,0,0,1,0,40", "same point");
  expectError(path("store") + " -o " + path("x.png") + " --camera-file " + path("missing.json"), "missing.json", 3);
  expectError(path("store") + " -o " + path("x.png") + " --size 0x10", "--size");
  expectError(path("store") + " -o " + path("x.png") + " --radius 12", "border");
  expectError(path("nowhere") + " -o " + path("x.png"), "nowhere", 3);
  expectError(path("store") + " -o " + path("x.png") + " --smoothing gaussian",
              "valid values: rof, bilateral");
  expectError(path("store") + " -o " + path("x.png") + " --smoothing-iterations 20000", "valid values: 0..10000");
  expectError(path("store") + " -o " + path("x.png") + " --smoothing-strength -1", "--smoothing-strength");
  expectError(path("store") + " -o " + path("x.png") + " --smoothing rof --smoothing-strength 1e9",
              "valid values: 0..");
  expectError(path("store") + " -o " + path("x.png") + " --shading glass",
              "valid values: liquid, spheres, attribute, normals");
  expectError(path("store") + " -o " + path("x.png") + " --env " + path("missing.exr"), "missing.exr", 3);
  expectError(path("store") + " -o " + path("x.png") + " --foam bubbles", "valid values: volume, remove, keep");
  expectError(path("store") + " -o " + path("x.png") + " --foam-from guess", "valid values: classify, kind, both");
  expectError(path("store") + " -o " + path("x.png") + " --foam-threshold 1.5", "--foam-threshold");
  expectError(path("store") + " -o " + path("x.png") + " --foam-threshold -0.1", "--foam-threshold");
  EXPECT_FALSE(fs::exists(path("x.png")));

  // Damaged brick payloads: the error names the frame file; no image is left behind.
  const fs::path frame = dir / "store" / "frame_000000.fsf";
  {
    const auto size = std::streamoff(fs::file_size(frame));
    std::fstream f(frame, std::ios::in | std::ios::out | std::ios::binary);
    for (std::streamoff offset = 16; offset < size / 2; offset += 61) {
      f.seekp(offset);
      f.put('\x5a');
    }
  }
  expectError(path("store") + " -o " + path("x.png") + " --size 32x18 --device cpu", "frame_000000.fsf", 3);
  EXPECT_FALSE(fs::exists(path("x.png")));
}

TEST(Demo, RendersAPreviewImage) {
  flipscope::testing::TempDir temp("demo");
  CommandRun demo =
      runFlipscope("demo -o " + (temp.path() / "out").string() + " --particles 50k --frames 2 --size 96x54");
  ASSERT_EQ(demo.exitCode, 0) << demo.output;
  EXPECT_EQ(pngSize(temp.path() / "out" / "preview.png"), std::make_pair(96u, 54u));
  EXPECT_NE(demo.output.find("preview.png"), std::string::npos) << demo.output;
}

}  // namespace
