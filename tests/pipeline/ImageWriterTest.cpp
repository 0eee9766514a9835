// ImageWriter: EXR round trips (channel names, half RGBA, exact float depth and normals), PNG
// sRGB encoding read back with libpng, extension dispatch, and atomic writes that leave no
// temporary file behind when they fail.
#include <gtest/gtest.h>
#include <png.h>

#include <Imath/half.h>
#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "TestSupport.h"
#include "core/Error.h"
#include "pipeline/ImageWriter.h"

namespace {

namespace fs = std::filesystem;
using flipscope::ExrContents;
using flipscope::RenderImage;

/// A random image: about a quarter of the pixels empty (alpha 0, depth +inf, normal 0).
RenderImage randomImage(std::uint32_t width, std::uint32_t height, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::normal_distribution<float> gauss;
  RenderImage image;
  image.width = width;
  image.height = height;
  const std::size_t n = std::size_t(width) * height;
  image.rgba.resize(n);
  image.depth.resize(n);
  image.normal.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (unit(rng) < 0.25f) {
      image.rgba[i] = glm::vec4(0.0f);
      image.depth[i] = std::numeric_limits<float>::infinity();
      image.normal[i] = glm::vec3(0.0f);
      continue;
    }
    const float a = 0.1f + 0.9f * unit(rng);
    image.rgba[i] = glm::vec4(3.0f * unit(rng) * a, unit(rng) * a, unit(rng) * a, a);
    image.depth[i] = 0.01f + 100.0f * unit(rng);
    glm::vec3 n3(gauss(rng), gauss(rng), gauss(rng));
    image.normal[i] = n3 / std::sqrt(n3.x * n3.x + n3.y * n3.y + n3.z * n3.z + 1e-12f);
  }
  return image;
}

/// Names of the temporary files AtomicFile leaves in `dir` (".<name>.tmp-...").
std::vector<std::string> temporaryFiles(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.find(".tmp-") != std::string::npos) names.push_back(name);
  }
  return names;
}

struct PngPixels {
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
};

PngPixels readPng(const fs::path& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  PngPixels result;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    ADD_FAILURE() << "libpng cannot read " << path << ": " << png.message;
    return result;
  }
  png.format = PNG_FORMAT_RGBA;
  result.width = png.width;
  result.height = png.height;
  result.rgba.resize(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, result.rgba.data(), 0, nullptr)) {
    ADD_FAILURE() << "libpng cannot decode " << path << ": " << png.message;
    png_image_free(&png);
  }
  return result;
}

class ImageWriter : public ::testing::Test {
 protected:
  flipscope::testing::TempDir temp{"imagewriter"};
  const fs::path& dir = temp.path();
};

TEST_F(ImageWriter, ExrRoundTripKeepsChannelsAndValues) {
  const RenderImage image = randomImage(13, 7, 1);
  flipscope::writeExr(dir / "a.exr", image);
  const ExrContents contents = flipscope::readExr(dir / "a.exr");

  // OpenEXR stores channels sorted by name.
  EXPECT_EQ(contents.channels, (std::vector<std::string>{"A", "B", "G", "N.X", "N.Y", "N.Z", "R", "Z"}));
  const RenderImage& read = contents.image;
  ASSERT_EQ(read.width, image.width);
  ASSERT_EQ(read.height, image.height);
  ASSERT_EQ(read.rgba.size(), image.rgba.size());
  ASSERT_EQ(read.depth.size(), image.depth.size());
  ASSERT_EQ(read.normal.size(), image.normal.size());
  for (std::size_t i = 0; i < image.rgba.size(); ++i) {
    for (int c = 0; c < 4; ++c)
      EXPECT_EQ(read.rgba[i][c], float(Imath::half(image.rgba[i][c]))) << "pixel " << i << " channel " << c;
    EXPECT_EQ(read.depth[i], image.depth[i]) << "pixel " << i;  // exact, +inf included
    EXPECT_EQ(read.normal[i], image.normal[i]) << "pixel " << i;
  }
  EXPECT_TRUE(temporaryFiles(dir).empty());
}

TEST_F(ImageWriter, ExrWithoutDepthAndNormalsHasRgbaOnly) {
  RenderImage image = randomImage(4, 3, 2);
  image.depth.clear();
  image.normal.clear();
  flipscope::writeImage(dir / "b.EXR", image);  // the extension is matched in any case
  const ExrContents contents = flipscope::readExr(dir / "b.EXR");
  EXPECT_EQ(contents.channels, (std::vector<std::string>{"A", "B", "G", "R"}));
  EXPECT_TRUE(contents.image.depth.empty());
  EXPECT_TRUE(contents.image.normal.empty());
}

TEST_F(ImageWriter, ExrOverwritesAnExistingFile) {
  const RenderImage first = randomImage(5, 5, 3);
  const RenderImage second = randomImage(6, 2, 4);
  flipscope::writeExr(dir / "c.exr", first);
  flipscope::writeExr(dir / "c.exr", second);
  const ExrContents contents = flipscope::readExr(dir / "c.exr");
  EXPECT_EQ(contents.image.width, 6u);
  EXPECT_EQ(contents.image.height, 2u);
  EXPECT_EQ(contents.image.depth, second.depth);
}

TEST_F(ImageWriter, ReadExrRejectsMissingAndTruncatedFiles) {
  try {
    flipscope::readExr(dir / "missing.exr");
    ADD_FAILURE() << "no error for a missing file";
  } catch (const flipscope::FileError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.exr"), std::string::npos) << e.what();
  }
  flipscope::writeExr(dir / "t.exr", randomImage(64, 64, 5));
  fs::resize_file(dir / "t.exr", fs::file_size(dir / "t.exr") / 2);
  EXPECT_THROW(flipscope::readExr(dir / "t.exr"), flipscope::FileError);
}

TEST_F(ImageWriter, TheSrgbTableGivesTheFormulasCodeForEveryFloat) {
  // Where the table could go wrong: at the first float of each code, and the one before it
  // (found here by bisection over the bit patterns, as the table's are), and in between.
  for (int code = 1; code < 256; ++code) {
    std::uint32_t lo = 0, hi = std::bit_cast<std::uint32_t>(1.0f);
    while (lo < hi) {
      const std::uint32_t mid = lo + (hi - lo) / 2;
      if (flipscope::linearToSrgb8Formula(std::bit_cast<float>(mid)) >= code)
        hi = mid;
      else
        lo = mid + 1;
    }
    for (const std::uint32_t bits : {lo - 1, lo, lo + 1}) {
      const float x = std::bit_cast<float>(bits);
      ASSERT_EQ(flipscope::linearToSrgb8(x), flipscope::linearToSrgb8Formula(x)) << "x = " << x << ", code " << code;
    }
    EXPECT_EQ(flipscope::linearToSrgb8(std::bit_cast<float>(lo)), code);
  }
  for (std::uint32_t bits = 0; bits <= std::bit_cast<std::uint32_t>(1.0f); bits += 997) {
    const float x = std::bit_cast<float>(bits);
    ASSERT_EQ(flipscope::linearToSrgb8(x), flipscope::linearToSrgb8Formula(x)) << "x = " << x;
  }
  for (const float x :
       {-0.0f, -1e-30f, 1.0f, 1.5f, std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
        std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::denorm_min()})
    EXPECT_EQ(flipscope::linearToSrgb8(x), flipscope::linearToSrgb8Formula(x)) << "x = " << x;
}

TEST_F(ImageWriter, SrgbEncodingOfKnownValues) {
  EXPECT_EQ(flipscope::linearToSrgb8(0.0f), 0);
  EXPECT_EQ(flipscope::linearToSrgb8(-1.0f), 0);
  EXPECT_EQ(flipscope::linearToSrgb8(std::numeric_limits<float>::quiet_NaN()), 0);
  EXPECT_EQ(flipscope::linearToSrgb8(0.001f), 3);       // linear segment: 12.92 * 0.001 * 255 = 3.29
  EXPECT_EQ(flipscope::linearToSrgb8(0.0031308f), 10);  // the knee: 0.04045 * 255 = 10.3
  EXPECT_EQ(flipscope::linearToSrgb8(0.18f), 118);      // middle grey: 0.4614 * 255 = 117.6
  EXPECT_EQ(flipscope::linearToSrgb8(0.5f), 188);       // 0.7354 * 255 = 187.5
  EXPECT_EQ(flipscope::linearToSrgb8(1.0f), 255);
  EXPECT_EQ(flipscope::linearToSrgb8(7.0f), 255);
  for (int code = 0; code < 256; code += 5) {  // the decoding formula inverts it
    const double s = code / 255.0;
    const double linear = s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
    EXPECT_EQ(flipscope::linearToSrgb8(float(linear)), code);
  }
}

TEST_F(ImageWriter, PngIsUnpremultipliedSrgbRgba8) {
  RenderImage image;
  image.width = 3;
  image.height = 2;
  image.rgba = {glm::vec4(0.5f * 0.5f, 0.18f * 0.5f, 1.0f * 0.5f, 0.5f),  // premultiplied by 0.5
                glm::vec4(0.0f),
                glm::vec4(2.0f, 0.0f, 0.001f, 1.0f),
                glm::vec4(1.0f, 1.0f, 1.0f, 1.0f),
                glm::vec4(0.0f, 0.0f, 0.0f, 1.0f),
                glm::vec4(0.5f, 0.5f, 0.5f, 0.0f)};  // alpha 0: written as transparent black
  flipscope::writePng(dir / "p.png", image);
  const PngPixels png = readPng(dir / "p.png");
  ASSERT_EQ(png.width, 3u);
  ASSERT_EQ(png.height, 2u);
  const std::vector<std::uint8_t> expected = {188, 118, 255, 128,  // row 0
                                              0,   0,   0,   0,    //
                                              255, 0,   3,   255,  //
                                              255, 255, 255, 255,  // row 1
                                              0,   0,   0,   255,  //
                                              0,   0,   0,   0};
  EXPECT_EQ(png.rgba, expected);

  // The file says it is sRGB (an sRGB chunk before the image data).
  std::ifstream file(dir / "p.png", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  EXPECT_EQ(bytes.substr(1, 3), "PNG");
  EXPECT_NE(bytes.find("sRGB"), std::string::npos);
  EXPECT_LT(bytes.find("sRGB"), bytes.find("IDAT"));
  EXPECT_TRUE(temporaryFiles(dir).empty());
}

TEST_F(ImageWriter, WriteImageChoosesByExtension) {
  const RenderImage image = randomImage(4, 4, 6);
  flipscope::writeImage(dir / "w.png", image);
  flipscope::writeImage(dir / "w.exr", image);
  EXPECT_EQ(readPng(dir / "w.png").width, 4u);
  EXPECT_EQ(flipscope::readExr(dir / "w.exr").channels.size(), 8u);
  for (const char* name : {"w.tif", "w", "w.exr.tmp"}) {
    try {
      flipscope::writeImage(dir / name, image);
      ADD_FAILURE() << "no error for " << name;
    } catch (const flipscope::FileError& e) {
      ADD_FAILURE() << "a bad extension is bad input, not a bad file: " << e.what();
    } catch (const flipscope::InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find((dir / name).string()), std::string::npos) << what;
      EXPECT_NE(what.find("must end in .exr or .png"), std::string::npos) << what;
    }
    EXPECT_FALSE(fs::exists(dir / name));
  }
}

TEST_F(ImageWriter, MissingDirectoryGivesFileErrorNamingTheFile) {
  const RenderImage image = randomImage(4, 4, 7);
  for (const char* name : {"x.exr", "x.png"}) {
    const fs::path path = dir / "no-such-dir" / name;
    try {
      flipscope::writeImage(path, image);
      ADD_FAILURE() << "no error for " << path;
    } catch (const flipscope::FileError& e) {
      EXPECT_EQ(e.path(), path);
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(temporaryFiles(dir).empty());
}

TEST_F(ImageWriter, FailedRenameLeavesNoTemporaryFile) {
  // The destination is a directory: the whole image is written to the temporary file, then the
  // rename fails, and the temporary file must go.
  const RenderImage image = randomImage(16, 16, 8);
  for (const char* name : {"d.exr", "d.png"}) {
    fs::create_directory(dir / name);
    EXPECT_THROW(flipscope::writeImage(dir / name, image), flipscope::FileError) << name;
    EXPECT_TRUE(fs::is_directory(dir / name));
  }
  EXPECT_EQ(temporaryFiles(dir), std::vector<std::string>{});
}

TEST_F(ImageWriter, UnwritableDestinationGivesFileErrorNamingIt) {
  // A regular file where the directory should be: no temporary file can be created, even as root.
  std::ofstream(dir / "plain") << "not a directory";
  for (const char* name : {"plain/r.exr", "plain/r.png"}) {
    try {
      flipscope::writeImage(dir / name, randomImage(4, 4, 9));
      ADD_FAILURE() << name << " was written";
    } catch (const flipscope::FileError& e) {
      EXPECT_NE(std::string(e.what()).find("plain"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(temporaryFiles(dir).size(), 0u);
}

TEST_F(ImageWriter, PngEncoderFailureGivesFileErrorAndNoFile) {
  // libpng refuses widths above its default user limit of 1,000,000 pixels.
  RenderImage image;
  image.width = 1'000'001;
  image.height = 1;
  image.rgba.assign(image.width, glm::vec4(1.0f));
  EXPECT_THROW(flipscope::writePng(dir / "wide.png", image), flipscope::FileError);
  EXPECT_FALSE(fs::exists(dir / "wide.png"));
  EXPECT_TRUE(temporaryFiles(dir).empty());
}

TEST_F(ImageWriter, InconsistentImageIsAProgrammerError) {
  RenderImage image = randomImage(4, 4, 10);
  image.depth.pop_back();
  EXPECT_THROW(flipscope::writeExr(dir / "bad.exr", image), flipscope::LogicError);
  EXPECT_THROW(flipscope::writePng(dir / "bad.png", RenderImage{}), flipscope::LogicError);
  EXPECT_TRUE(fs::is_empty(dir));
}

}  // namespace
