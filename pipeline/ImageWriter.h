// Rendered images and their files: OpenEXR (linear colour, depth and normals, for compositing)
// and PNG (8-bit sRGB, for a quick look). Every write is atomic (core/AtomicFile.h): a reader
// sees the old file or the complete new one, never a partial one.
//
// EXR channels: R G B A (HALF, linear, premultiplied), Z (FLOAT, camera depth in world units,
// +inf where nothing was hit; the smoothed surface's), unsmoothed.Z (FLOAT, the sphere depth
// before smoothing), thickness (FLOAT, liquid along the ray behind the surface, world units),
// N.X N.Y N.Z (FLOAT, world-space normal, 0 where nothing was hit) and, when the store has a
// per-particle attribute, a FLOAT channel named after it (speed, pscale, ...: its value at the
// surface, 0 where nothing was hit; see attributeChannel) and, with volumetric foam, the layer
// foam (foam.R foam.G foam.B foam.A, HALF: its premultiplied colour and opacity). The normal is a layer "N" in the
// OpenEXR "layer.channel" naming: Nuke splits at the first '.', shows layer N with channels X, Y,
// Z (only R/G/B/A suffixes are renamed to red/green/blue/alpha), and sorts them in x, y, z order;
// Houdini's EXR reader groups the N.* channels into one vector plane N; OpenImageIO keeps X, Y, Z
// in that order as spatial data.
// Upper-case suffixes match the upper-case R, G, B, A, Z of the file itself.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace flipscope {

/// A rendered image, row 0 at the top, pixel (x, y) at index y * width + x.
struct RenderImage {
  std::uint32_t width = 0, height = 0;
  std::vector<glm::vec4> rgba;         ///< linear RGB, premultiplied alpha; width * height
  std::vector<float> depth;            ///< camera depth, world units, +inf where alpha is 0; empty or width * height
  std::vector<glm::vec3> normal;       ///< world-space unit normal, 0 where nothing was hit; empty or width * height
  std::vector<float> unsmoothedDepth;  ///< like depth, before smoothing; empty or width * height
  std::vector<float> thickness;        ///< world units, 0 where nothing was hit; empty or width * height
  /// The volumetric foam (§3.5) composited into rgba: its colour premultiplied by its opacity,
  /// and the opacity; empty or width * height. EXR layer foam (foam.R foam.G foam.B foam.A, HALF).
  std::vector<glm::vec4> foam;
  /// The per-particle attribute of the store at each pixel (its units, 0 where nothing was hit),
  /// empty or width * height, in the EXR channel attributeChannel(attributeName).
  std::vector<float> attribute;
  std::string attributeName;
};

/// The EXR channel of an attribute: its name, or "attribute.<name>" when the name is one of the
/// channels writeExr writes anyway (R, G, B, A, Z, unsmoothed.Z, thickness, N.X, N.Y, N.Z, foam.*) or empty.
std::string attributeChannel(const std::string& attributeName);

/// Writes R G B A (HALF), Z, unsmoothed.Z, thickness, N.X N.Y N.Z and the attribute (FLOAT), and
/// foam.R foam.G foam.B foam.A (HALF), each only when its vector is not empty,
/// ZIP compressed. Throws FileError naming `path`.
void writeExr(const std::filesystem::path& path, const RenderImage& image);

/// Writes 8-bit RGBA: un-premultiplied, clamped to [0, 1] and sRGB encoded (sRGB chunk).
/// Throws FileError naming `path`.
void writePng(const std::filesystem::path& path, const RenderImage& image);

/// Whether writeImage takes `path`: it ends in .exr or .png, in any case.
bool isImagePath(const std::filesystem::path& path);

/// writeExr or writePng by the extension (.exr or .png, any case). Throws InputError naming
/// `path` for any other extension.
void writeImage(const std::filesystem::path& path, const RenderImage& image);

/// What readExr found: every channel name of the file (in the file's, alphabetical, order) and
/// the image. Missing R, G, B read as 0 and a missing A as 1; depth and normal stay empty
/// unless the file has Z, or N.X, N.Y and N.Z; unsmoothedDepth, thickness and foam likewise. Every
/// other channel (an attribute's) is read as FLOAT into `others`, by name.
struct ExrContents {
  std::vector<std::string> channels;
  RenderImage image;
  std::map<std::string, std::vector<float>> others;
};

/// Reads an EXR written by writeExr (or any scan-line or tiled single-part EXR with those
/// channels). For tests and checks. Throws FileError naming `path`.
ExrContents readExr(const std::filesystem::path& path);

/// Whether writeImage keeps the image's layers beyond its colour (depth, normals, thickness,
/// foam, the attribute channel) in a file named `path`: an EXR does, a PNG holds the final look
/// only.
bool keepsImageLayers(const std::filesystem::path& path);

/// sRGB encoding (IEC 61966-2-1) of a linear value clamped to [0, 1], as an 8-bit code
/// (rounded to nearest). NaN gives 0. From a table: the code linearToSrgb8Formula gives.
std::uint8_t linearToSrgb8(float linear);
/// The same by the formula (a pow a call): what the table is made from and checked against.
std::uint8_t linearToSrgb8Formula(float linear);

}  // namespace flipscope
