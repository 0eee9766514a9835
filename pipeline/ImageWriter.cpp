#include "pipeline/ImageWriter.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <png.h>

#include <Imath/half.h>
#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>

#include "core/AtomicFile.h"
#include "core/Error.h"

namespace flipscope {

namespace {

constexpr const char* kNormalChannels[3] = {"N.X", "N.Y", "N.Z"};
constexpr const char* kUnsmoothedDepthChannel = "unsmoothed.Z";
constexpr const char* kThicknessChannel = "thickness";
constexpr const char* kFoamChannels[4] = {"foam.R", "foam.G", "foam.B", "foam.A"};

std::size_t pixelCount(const RenderImage& image) { return std::size_t(image.width) * image.height; }

void checkImage(const RenderImage& image) {
  const std::size_t n = pixelCount(image);
  FLIPSCOPE_CHECK(image.width > 0 && image.height > 0 && image.width <= 0x7fffffffu && image.height <= 0x7fffffffu,
                  "width=" << image.width << " height=" << image.height);
  FLIPSCOPE_CHECK(image.rgba.size() == n, "rgba=" << image.rgba.size() << " pixels=" << n);
  FLIPSCOPE_CHECK(image.depth.empty() || image.depth.size() == n, "depth=" << image.depth.size() << " pixels=" << n);
  FLIPSCOPE_CHECK(image.normal.empty() || image.normal.size() == n,
                  "normal=" << image.normal.size() << " pixels=" << n);
  FLIPSCOPE_CHECK(image.unsmoothedDepth.empty() || image.unsmoothedDepth.size() == n,
                  "unsmoothedDepth=" << image.unsmoothedDepth.size() << " pixels=" << n);
  FLIPSCOPE_CHECK(image.thickness.empty() || image.thickness.size() == n,
                  "thickness=" << image.thickness.size() << " pixels=" << n);
  FLIPSCOPE_CHECK(image.attribute.empty() || image.attribute.size() == n,
                  "attribute=" << image.attribute.size() << " pixels=" << n);
  FLIPSCOPE_CHECK(image.foam.empty() || image.foam.size() == n, "foam=" << image.foam.size() << " pixels=" << n);
}

/// Every channel writeExr writes besides an attribute's.
bool isImageChannel(const std::string& name) {
  for (const char* channel :
       {"R", "G", "B", "A", "Z", kUnsmoothedDepthChannel, kThicknessChannel, kNormalChannels[0], kNormalChannels[1],
        kNormalChannels[2], kFoamChannels[0], kFoamChannels[1], kFoamChannels[2], kFoamChannels[3]})
    if (name == channel) return true;
  return false;
}

/// Runs `work` and turns any failure into an `Error` (OutputError for writes, FileError for
/// reads) naming `path`.
template <typename Error, typename Work>
void reportingErrors(const std::filesystem::path& path, Work&& work) {
  try {
    work();
  } catch (const FileError& e) {
    if (e.path() == path && dynamic_cast<const Error*>(&e)) throw;
    throw Error(path, e.what());  // names the temporary file too
  } catch (const LogicError&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(path, e.what());
  }
}

/// An Imf::OStream onto an AtomicFile: OpenEXR seeks back to fill in its line offset table,
/// which AtomicFile::writeAt allows. OpenEXR swallows errors raised while it finishes the file
/// in ~OutputFile, so the first error is also kept in failure().
class AtomicFileStream : public Imf::OStream {
 public:
  explicit AtomicFileStream(AtomicFile& file) : Imf::OStream(file.temporaryPath().c_str()), mFile(file) {}

  void write(const char c[], int n) override {
    try {
      std::uint64_t bytes = std::uint64_t(std::max(n, 0));
      if (mPosition < mFile.offset()) {
        const std::uint64_t overlap = std::min(bytes, mFile.offset() - mPosition);
        mFile.writeAt(mPosition, c, overlap);
        c += overlap;
        bytes -= overlap;
        mPosition += overlap;
      }
      if (bytes) {
        mFile.write(c, bytes);
        mPosition += bytes;
      }
    } catch (const std::exception& e) {
      if (!mFailure) mFailure = e.what();
      throw;
    }
  }
  std::uint64_t tellp() override { return mPosition; }
  void seekp(std::uint64_t position) override {
    if (position > mFile.offset()) {
      if (!mFailure) mFailure = "OpenEXR seeked past the end of the file";
      throw std::runtime_error(*mFailure);
    }
    mPosition = position;
  }
  const std::optional<std::string>& failure() const { return mFailure; }

 private:
  AtomicFile& mFile;
  std::uint64_t mPosition = 0;
  std::optional<std::string> mFailure;
};

std::string lowerExtension(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
  return extension;
}

}  // namespace

std::string attributeChannel(const std::string& attributeName) {
  return attributeName.empty() || isImageChannel(attributeName) ? "attribute." + attributeName : attributeName;
}

void writeExr(const std::filesystem::path& path, const RenderImage& image) {
  checkImage(image);
  const std::size_t n = pixelCount(image);
  const std::size_t width = image.width;

  Imf::Header header(int(image.width), int(image.height));
  header.compression() = Imf::ZIP_COMPRESSION;
  Imf::FrameBuffer frame;
  // Four HALF channels from a vec4 image, converted into `storage` (kept alive until written).
  auto insertHalf4 = [&](const char* const(&names)[4], const std::vector<glm::vec4>& values,
                         std::vector<Imath::half>& storage) {
    if (values.empty()) return;
    storage.resize(4 * n);
    for (std::size_t i = 0; i < n; ++i)
      for (int c = 0; c < 4; ++c) storage[4 * i + c] = Imath::half(values[i][c]);
    for (int c = 0; c < 4; ++c) {
      header.channels().insert(names[c], Imf::Channel(Imf::HALF));
      frame.insert(names[c], Imf::Slice(Imf::HALF, reinterpret_cast<char*>(storage.data() + c), 4 * sizeof(Imath::half),
                                        4 * sizeof(Imath::half) * width));
    }
  };
  constexpr const char* kRgba[4] = {"R", "G", "B", "A"};
  std::vector<Imath::half> rgba, foam;
  insertHalf4(kRgba, image.rgba, rgba);
  insertHalf4(kFoamChannels, image.foam, foam);
  auto insertFloat = [&](const char* name, const std::vector<float>& values) {
    if (values.empty()) return;
    header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    frame.insert(name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(values.data())), sizeof(float),
                                  sizeof(float) * width));
  };
  insertFloat("Z", image.depth);
  insertFloat(kUnsmoothedDepthChannel, image.unsmoothedDepth);
  insertFloat(kThicknessChannel, image.thickness);
  const std::string attribute = attributeChannel(image.attributeName);
  insertFloat(attribute.c_str(), image.attribute);
  if (!image.normal.empty()) {
    char* base = reinterpret_cast<char*>(const_cast<glm::vec3*>(image.normal.data()));
    for (int c = 0; c < 3; ++c) {
      header.channels().insert(kNormalChannels[c], Imf::Channel(Imf::FLOAT));
      frame.insert(kNormalChannels[c],
                   Imf::Slice(Imf::FLOAT, base + c * sizeof(float), sizeof(glm::vec3), sizeof(glm::vec3) * width));
    }
  }

  reportingErrors<OutputError>(path, [&] {
    AtomicFile file(path);
    AtomicFileStream stream(file);
    {
      Imf::OutputFile exr(stream, header);
      exr.setFrameBuffer(frame);
      exr.writePixels(int(image.height));
    }  // ~OutputFile writes the line offset table
    if (stream.failure()) throw OutputError(path, "write failed: " + *stream.failure());
    file.commit();
  });
}

std::uint8_t linearToSrgb8Formula(float linear) {
  if (!(linear > 0.0f)) return 0;  // also NaN
  if (linear >= 1.0f) return 255;
  const double v = linear <= 0.0031308f ? 12.92 * linear : 1.055 * std::pow(double(linear), 1.0 / 2.4) - 0.055;
  return std::uint8_t(std::lround(v * 255.0));
}

namespace {

/// linearToSrgb8Formula without its pow (a PNG's three a pixel were a fifth of writing it), to
/// the same code for every float: the formula rises with its input, so the code of x is the
/// number of codes whose first float (found once, by bisection over the float bit patterns of
/// [0, 1]) is at most x. A table per 2^16 bit patterns gives the code where the bucket starts;
/// the few buckets that hold the first float of the next code (no bucket holds two: the
/// steepest part, at 0, climbs 0.08 codes a bucket) step on to it.
class SrgbTable {
 public:
  SrgbTable() {
    mFirst[0] = 0.0f;
    for (int code = 1; code < 256; ++code) {
      std::uint32_t lo = 0, hi = std::bit_cast<std::uint32_t>(1.0f);  // the formula gives 255 at hi
      while (lo < hi) {
        const std::uint32_t mid = lo + (hi - lo) / 2;
        if (linearToSrgb8Formula(std::bit_cast<float>(mid)) >= code)
          hi = mid;
        else
          lo = mid + 1;
      }
      mFirst[std::size_t(code)] = std::bit_cast<float>(lo);
    }
    mFirst[256] = std::numeric_limits<float>::infinity();
    for (std::uint32_t b = 0; b < kBuckets; ++b) mBucket[b] = linearToSrgb8Formula(std::bit_cast<float>(b << kShift));
  }
  std::uint8_t operator()(float linear) const {
    if (!(linear > 0.0f)) return 0;  // also NaN
    if (linear >= 1.0f) return 255;
    std::uint32_t code = mBucket[std::bit_cast<std::uint32_t>(linear) >> kShift];
    while (linear >= mFirst[code + 1]) ++code;
    return std::uint8_t(code);
  }

 private:
  static constexpr std::uint32_t kShift = 16;
  static constexpr std::uint32_t kBuckets = (std::bit_cast<std::uint32_t>(1.0f) >> kShift) + 1;
  std::array<float, 257> mFirst;  ///< the first float of each code; then +inf
  std::array<std::uint8_t, kBuckets> mBucket;
};

}  // namespace

std::uint8_t linearToSrgb8(float linear) {
  static const SrgbTable table;
  return table(linear);
}

void writePng(const std::filesystem::path& path, const RenderImage& image) {
  checkImage(image);
  const std::size_t n = pixelCount(image);
  std::vector<std::uint8_t> pixels(4 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec4 p = image.rgba[i];
    if (!(p.a > 0.0f)) continue;  // transparent black (also for a NaN alpha)
    for (int c = 0; c < 3; ++c) pixels[4 * i + c] = linearToSrgb8(p[c] / p.a);
    pixels[4 * i + 3] = std::uint8_t(std::lround(std::min(p.a, 1.0f) * 255.0f));
  }
  // libpng's simplified API: no setjmp here, and an sRGB chunk for 8-bit data.
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = image.width;
  png.height = image.height;
  png.format = PNG_FORMAT_RGBA;
  std::vector<std::byte> encoded(PNG_IMAGE_PNG_SIZE_MAX(png));
  png_alloc_size_t bytes = encoded.size();
  const bool ok = png_image_write_to_memory(&png, encoded.data(), &bytes, 0, pixels.data(), 0, nullptr);
  const std::string message = png.message;
  png_image_free(&png);
  if (!ok) throw OutputError(path, "libpng cannot encode the image: " + message);
  encoded.resize(bytes);
  reportingErrors<OutputError>(path, [&] { writeFileAtomically(path, encoded); });
}

bool keepsImageLayers(const std::filesystem::path& path) { return lowerExtension(path) == ".exr"; }

bool isImagePath(const std::filesystem::path& path) {
  const std::string extension = lowerExtension(path);
  return extension == ".exr" || extension == ".png";
}

void writeImage(const std::filesystem::path& path, const RenderImage& image) {
  const std::string extension = lowerExtension(path);
  if (extension == ".exr")
    writeExr(path, image);
  else if (extension == ".png")
    writePng(path, image);
  else
    throw InputError(path.string() + ": image file name must end in .exr or .png");
}

ExrContents readExr(const std::filesystem::path& path) {
  ExrContents contents;
  reportingErrors<FileError>(path, [&] {
    Imf::InputFile exr(path.c_str());
    const Imf::Header& header = exr.header();
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it)
      contents.channels.emplace_back(it.name());
    const Imath::Box2i window = header.dataWindow();
    RenderImage& image = contents.image;
    image.width = std::uint32_t(window.max.x - window.min.x + 1);
    image.height = std::uint32_t(window.max.y - window.min.y + 1);
    const std::size_t n = pixelCount(image);
    const auto has = [&](const char* name) { return header.channels().findChannel(name) != nullptr; };

    Imf::FrameBuffer frame;
    image.rgba.assign(n, glm::vec4(0.0f));
    constexpr const char* kRgba[4] = {"R", "G", "B", "A"};
    for (int c = 0; c < 4; ++c)
      frame.insert(kRgba[c], Imf::Slice::Make(Imf::FLOAT, &image.rgba[0][c], window, sizeof(glm::vec4), 0, 1, 1,
                                              c == 3 ? 1.0 : 0.0));
    auto readFloat = [&](const char* name, std::vector<float>& values) {
      if (!has(name)) return;
      values.assign(n, 0.0f);
      frame.insert(name, Imf::Slice::Make(Imf::FLOAT, values.data(), window, sizeof(float)));
    };
    readFloat("Z", image.depth);
    readFloat(kUnsmoothedDepthChannel, image.unsmoothedDepth);
    readFloat(kThicknessChannel, image.thickness);
    if (has(kFoamChannels[0]) && has(kFoamChannels[1]) && has(kFoamChannels[2]) && has(kFoamChannels[3])) {
      image.foam.assign(n, glm::vec4(0.0f));
      for (int c = 0; c < 4; ++c)
        frame.insert(kFoamChannels[c], Imf::Slice::Make(Imf::FLOAT, &image.foam[0][c], window, sizeof(glm::vec4)));
    }
    if (has(kNormalChannels[0]) && has(kNormalChannels[1]) && has(kNormalChannels[2])) {
      image.normal.assign(n, glm::vec3(0.0f));
      for (int c = 0; c < 3; ++c)
        frame.insert(kNormalChannels[c], Imf::Slice::Make(Imf::FLOAT, &image.normal[0][c], window, sizeof(glm::vec3)));
    }
    for (const std::string& name : contents.channels) {
      if (isImageChannel(name)) continue;
      std::vector<float>& values = contents.others[name];
      values.assign(n, 0.0f);
      frame.insert(name, Imf::Slice::Make(Imf::FLOAT, values.data(), window, sizeof(float)));
    }
    exr.setFrameBuffer(frame);
    exr.readPixels(window.min.y, window.max.y);
  });
  return contents;
}

}  // namespace flipscope
