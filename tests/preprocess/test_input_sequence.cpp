// Input patterns and frame discovery for `flipscope convert`.
#include <gtest/gtest.h>

#include "ParticleTestSupport.h"
#include "preprocess/particles/InputSequence.h"

namespace flipscope {
namespace {

using testing::TempDir;

void createFile(const std::filesystem::path& path) { testing::writeBytes(path, "x"); }

TEST(InputSequence, SubstitutesEveryPatternKind) {
  EXPECT_EQ(substituteFrame("a/fluid_####.vdb", 7), "a/fluid_0007.vdb");
  EXPECT_EQ(substituteFrame("fluid_##.vdb", 1234), "fluid_1234.vdb");
  EXPECT_EQ(substituteFrame("f_%04d.ply", 12), "f_0012.ply");
  EXPECT_EQ(substituteFrame("f_%d.ply", 12), "f_12.ply");
  EXPECT_EQ(substituteFrame("f_{}.bin", 3), "f_3.bin");
  EXPECT_EQ(substituteFrame("plain.vdb", 3), "plain.vdb");
  EXPECT_EQ(substituteFrame("splash.$F4.bgeo.sc", 12), "splash.0012.bgeo.sc");
  EXPECT_EQ(substituteFrame("splash.$F.bgeo.sc", 12), "splash.12.bgeo.sc");
  EXPECT_EQ(substituteFrame("a/$FPS/b.$F2.geo", 3), "a/$FPS/b.03.geo");  // $FPS is another variable
  EXPECT_FALSE(hasFramePattern("x.$FSTART.bgeo"));
  EXPECT_TRUE(hasFramePattern("x_#.vdb"));
  EXPECT_TRUE(hasFramePattern("x_%03d.vdb"));
  EXPECT_TRUE(hasFramePattern("x_{}.vdb"));
  EXPECT_FALSE(hasFramePattern("x_100%.vdb"));
  EXPECT_FALSE(hasFramePattern("x_{.vdb"));
}

TEST(InputSequence, ParsesFrameRanges) {
  EXPECT_EQ(parseFrameRange("3-17").first, 3);
  EXPECT_EQ(parseFrameRange("3-17").last, 17);
  EXPECT_EQ(parseFrameRange("5").first, 5);
  EXPECT_EQ(parseFrameRange("5").last, 5);
  for (const char* bad : {"", "a", "3-", "-3", "5-3", "1-2-3", "1.5"}) {
    try {
      parseFrameRange(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("'") + bad + "'"), std::string::npos) << e.what();
    }
  }
}

TEST(InputSequence, DiscoversFramesInTheDirectory) {
  TempDir dir("seq-discover");
  for (int f : {12, 3, 100, 7}) createFile(dir / substituteFrame("fluid_####.vdb", f));
  createFile(dir / "fluid_12.vdb");    // wrong width: not frame 12 of ####
  createFile(dir / "fluid_0x12.vdb");  // not a number
  createFile(dir / "other_0005.vdb");
  for (std::string pattern : {"fluid_####.vdb", "fluid_%04d.vdb"}) {
    auto frames = expandInputs({(dir / pattern).string()}, std::nullopt);
    ASSERT_EQ(frames.size(), 4u) << pattern;
    std::vector<int> numbers;
    for (const auto& f : frames) {
      numbers.push_back(f.frame);
      ASSERT_EQ(f.files.size(), 1u);
      EXPECT_EQ(f.files[0], dir / substituteFrame("fluid_####.vdb", f.frame));
    }
    EXPECT_EQ(numbers, (std::vector<int>{3, 7, 12, 100}));
  }
  createFile(dir / "splash.0001.bgeo.sc");
  createFile(dir / "splash.0002.bgeo.sc");
  createFile(dir / "splash.0002.bgeo");  // another extension: not a frame of the .bgeo.sc pattern
  auto houdini = expandInputs({(dir / "splash.$F4.bgeo.sc").string()}, std::nullopt);
  ASSERT_EQ(houdini.size(), 2u);
  EXPECT_EQ(houdini[1].frame, 2);
  EXPECT_EQ(houdini[1].files[0], dir / "splash.0002.bgeo.sc");
  auto unpadded = expandInputs({(dir / "fluid_{}.vdb").string()}, std::nullopt);
  ASSERT_EQ(unpadded.size(), 1u);
  EXPECT_EQ(unpadded[0].frame, 12);
  testing::expectFileError([&] { expandInputs({(dir / "none_####.vdb").string()}, std::nullopt); },
                           {"no file matches input pattern", "none_####.vdb"});
}

TEST(InputSequence, ADirectoryGivenAsInputNamesTheSequencesItHolds) {
  TempDir dir("seq-folder");
  std::filesystem::create_directories(dir / "cache" / "data");
  std::filesystem::create_directories(dir / "cache" / "particles");
  for (int f : {1, 2, 10}) createFile(dir / "cache" / "data" / substituteFrame("fluid_data_####.vdb", f));
  createFile(dir / "cache" / "particles" / "fluid_particles_0001.vdb");
  createFile(dir / "cache" / "splash.1.bgeo.sc");
  createFile(dir / "cache" / "splash.12.bgeo.sc");  // unpadded: one '#'
  createFile(dir / "cache" / "notes_01.txt");       // not a particle file
  createFile(dir / "cache" / "fluid.vdb");          // not numbered
  const std::string cache = (dir / "cache").string();
  testing::expectFileError(
      [&] { expandInputs({cache}, std::nullopt); },
      {"cache: is a directory", "or a frame pattern",
       "'" + cache + "/data/fluid_data_####.vdb' (3 files), '" + cache + "/splash.#.bgeo.sc' (2 files), '" + cache +
           "/particles/fluid_particles_####.vdb' (1 file)"});
  try {
    expandInputs({cache}, std::nullopt);
  } catch (const FileError& e) {
    EXPECT_EQ(std::string(e.what()).find("notes"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find("fluid.vdb"), std::string::npos) << e.what();
  }
  std::filesystem::create_directories(dir / "empty");
  testing::expectFileError([&] { expandInputs({(dir / "empty").string()}, std::nullopt); },
                           {"empty: is a directory", "it holds no numbered particle files"});
}

TEST(InputSequence, FrameRangeAndTwoInputsPerFrame) {
  TempDir dir("seq-range");
  for (int f = 1; f <= 5; ++f) {
    createFile(dir / substituteFrame("data_####.vdb", f));
    createFile(dir / substituteFrame("spray_{}.vdb", f));
  }
  auto frames =
      expandInputs({(dir / "data_####.vdb").string(), (dir / "spray_{}.vdb").string()}, parseFrameRange("2-4"));
  ASSERT_EQ(frames.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(frames[i].frame, 2 + i);
    ASSERT_EQ(frames[i].files.size(), 2u);
    EXPECT_EQ(frames[i].files[0], dir / substituteFrame("data_####.vdb", 2 + i));
    EXPECT_EQ(frames[i].files[1], dir / substituteFrame("spray_{}.vdb", 2 + i));
  }
  auto discovered = expandInputs({(dir / "data_####.vdb").string(), (dir / "spray_{}.vdb").string()}, std::nullopt);
  EXPECT_EQ(discovered.size(), 5u);
}

TEST(InputSequence, MissingFileNamesPathAndFrame) {
  TempDir dir("seq-missing");
  for (int f = 1; f <= 4; ++f) createFile(dir / substituteFrame("data_####.vdb", f));
  for (int f : {1, 2, 4}) createFile(dir / substituteFrame("spray_%d.vdb", f));
  auto inputs = std::vector<std::string>{(dir / "data_####.vdb").string(), (dir / "spray_%d.vdb").string()};
  testing::expectFileError([&] { expandInputs(inputs, std::nullopt); }, {"spray_3.vdb", "frame 3", "spray_%d.vdb"});
  testing::expectFileError([&] { expandInputs(inputs, parseFrameRange("4-6")); }, {"data_0005.vdb", "frame 5"});
  EXPECT_EQ(expandInputs(inputs, parseFrameRange("1-2")).size(), 2u);
}

TEST(InputSequence, InputsWithoutPatternFormOneFrame) {
  TempDir dir("seq-single");
  createFile(dir / "a.ply");
  createFile(dir / "b.bin");
  auto frames = expandInputs({(dir / "a.ply").string(), (dir / "b.bin").string()}, std::nullopt);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].frame, 0);
  EXPECT_EQ(frames[0].files, (std::vector<std::filesystem::path>{dir / "a.ply", dir / "b.bin"}));
  EXPECT_EQ(expandInputs({(dir / "a.ply").string()}, parseFrameRange("9"))[0].frame, 9);
  testing::expectFileError([&] { expandInputs({(dir / "c.ply").string()}, std::nullopt); }, {"c.ply", "no such file"});
}

}  // namespace
}  // namespace flipscope
