// BrickStore: store header, frame files and brick reads (format in BrickStore.h, FrameFile.h).
#include "preprocess/store/BrickStore.h"

#include <fcntl.h>
#include <sys/random.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <mutex>
#include <random>
#include <set>

#include "core/Bytes.h"
#include "core/Hash.h"
#include "core/Morton.h"
#include "preprocess/store/FrameFile.h"
#include "preprocess/store/StoreLock.h"

namespace flipscope {
namespace {

constexpr char kStoreMagic[8] = {'F', 'S', 'S', 'T', 'O', 'R', 'E', '1'};
/// Fixed part of store.fsh: magic .. particle spacing, store id, run count; then 8 bytes a run
/// of the frame table, then the checksum. Version 4 adds the attribute name (length and bytes)
/// and the attribute range (flag, min, max) before the run count, version 5 the particle kinds
/// flag after them, version 6 the up axis after that.
constexpr std::size_t kStoreHeaderFixedBytes = 8 + 4 + 4 + 8 + 24 + 12 + 4 + 8 + 16 + 4;
constexpr std::size_t kStoreHeaderV4Bytes = 4 + 4 + 4 + 4;
constexpr std::size_t kStoreHeaderV5Bytes = 4;
constexpr std::size_t kStoreHeaderV6Bytes = 4;
/// The footer's version field, counted back from the end of the file.
constexpr std::uint64_t kFooterVersionFromEnd = 24;

bool isValidBrickSize(std::uint32_t b) { return b == 32 || b == 64 || b == 128; }

/// Consecutive frames first .. first + count - 1.
struct FrameRun {
  std::int32_t first;
  std::uint32_t count;
};

std::vector<FrameRun> runsOf(const std::vector<int>& frames) {
  std::vector<FrameRun> runs;
  for (int f : frames) {
    if (!runs.empty() && std::int64_t(runs.back().first) + runs.back().count == f)
      ++runs.back().count;
    else
      runs.push_back({f, 1});
  }
  return runs;
}

std::vector<int> serializeList(const std::set<int>& frames) { return {frames.begin(), frames.end()}; }

/// pread exactly `n` bytes at `offset`; FileError naming `what` when the file is shorter.
void readAt(int fd, const std::filesystem::path& file, std::uint64_t offset, void* out, std::size_t n, const char* what) {
  auto p = static_cast<char*>(out);
  while (n > 0) {
    ssize_t got = ::pread(fd, p, n, off_t(offset));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) throw FileError(file, std::string("read failed (") + what + "): " + std::strerror(errno));
    if (got == 0) throw FileError(file, std::string("truncated: ") + what + " ends past the end of the file");
    p += got;
    offset += std::uint64_t(got);
    n -= std::size_t(got);
  }
}

class FileHandle {
 public:
  explicit FileHandle(const std::filesystem::path& file) : mFd(::open(file.c_str(), O_RDONLY | O_CLOEXEC)) {
    if (mFd < 0) throw FileError(file, std::string("cannot open: ") + std::strerror(errno));
  }
  ~FileHandle() { ::close(mFd); }
  FileHandle(const FileHandle&) = delete;
  FileHandle& operator=(const FileHandle&) = delete;
  int fd() const { return mFd; }

 private:
  int mFd;
};

/// The footer in the layout of f.version.
void serializeFooter(ByteWriter& w, const FrameFooter& f) {
  w.put(f.octreeOffset);
  w.put(f.octreeLevels);
  w.put(f.nodeCount);
  w.put(f.tableOffset);
  w.put(f.brickCount);
  w.put(f.frame);
  w.put(f.stats.particles);
  w.put(f.stats.skippedInvalid);
  w.put(f.stats.skippedOutside);
  w.put(f.stats.attributeMin);
  w.put(f.stats.attributeMax);
  if (f.version >= 5)
    for (std::uint64_t cells : f.stats.kindCells) w.put(cells);
  w.append(f.storeId.data(), f.storeId.size());
  w.put(f.version);
  w.put(f.reserved);
}

/// A footer of `version` (read from its place first).
FrameFooter parseFooter(ByteReader& r, std::uint32_t version) {
  FrameFooter f;
  f.octreeOffset = r.get<std::uint64_t>("footer octree offset");
  f.octreeLevels = r.get<std::uint32_t>("footer octree levels");
  f.nodeCount = r.get<std::uint32_t>("footer node count");
  f.tableOffset = r.get<std::uint64_t>("footer table offset");
  f.brickCount = r.get<std::uint32_t>("footer brick count");
  f.frame = r.get<std::int32_t>("footer frame");
  f.stats.particles = r.get<std::uint64_t>("footer particles");
  f.stats.skippedInvalid = r.get<std::uint64_t>("footer skipped invalid");
  f.stats.skippedOutside = r.get<std::uint64_t>("footer skipped outside");
  f.stats.attributeMin = r.get<float>("footer attribute min");
  f.stats.attributeMax = r.get<float>("footer attribute max");
  static constexpr const char* kKindCellFields[kParticleKindCount] = {"footer liquid cells", "footer foam cells",
                                                                      "footer spray cells", "footer bubble cells"};
  if (version >= 5)
    for (std::uint32_t k = 0; k < kParticleKindCount; ++k) f.stats.kindCells[k] = r.get<std::uint64_t>(kKindCellFields[k]);
  auto id = r.getBytes(f.storeId.size(), "footer store id");
  std::memcpy(f.storeId.data(), id.data(), f.storeId.size());
  f.version = r.get<std::uint32_t>("footer version");
  f.reserved = r.get<std::uint32_t>("footer reserved");
  f.indexChecksum = r.get<std::uint64_t>("footer checksum");
  return f;
}

void serializeRecord(ByteWriter& w, const BrickRecord& b) {
  w.put(b.coord.x);
  w.put(b.coord.y);
  w.put(b.coord.z);
  w.put(b.particles);
  w.put(b.cells);
  w.put(b.bytes);
  w.put(b.offset);
  w.put(b.checksum);
}

}  // namespace

const char* attributeKindName(AttributeKind kind) {
  switch (kind) {
    case AttributeKind::None: return "none";
    case AttributeKind::Speed: return "speed";
    case AttributeKind::Scalar:
      return "scalar";
    case AttributeKind::Magnitude:
      return "magnitude";
  }
  return "unknown";
}

std::string frameFileName(int frame) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06d.fsf", frame);
  return name;
}

std::optional<int> frameFromFileName(const std::string& name) {
  if (name.size() != 16 || name.rfind("frame_", 0) != 0 || name.substr(12) != ".fsf") return std::nullopt;
  int frame = 0;
  for (char c : name.substr(6, 6)) {
    if (c < '0' || c > '9') return std::nullopt;
    frame = frame * 10 + (c - '0');
  }
  return frame;
}

StoreId randomStoreId() {
  StoreId id{};
  std::size_t filled = 0;
  while (filled < id.size()) {
    const ssize_t got = ::getrandom(id.data() + filled, id.size() - filled, 0);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;
    filled += std::size_t(got);
  }
  if (filled < id.size()) {  // no getrandom (old kernel, seccomp): the C++ library's source
    std::random_device device;
    for (auto& byte : id) byte = std::uint8_t(device());
  }
  if (id == StoreId{}) id[0] = 1;  // all zero means "no id"
  return id;
}

std::string storeIdText(const StoreId& id) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string text;
  for (auto byte : id) {
    text += kHex[byte >> 4];
    text += kHex[byte & 15];
  }
  return text;
}

// ---- store header ----------------------------------------------------------------------

std::vector<std::byte> serializeStoreHeader(const StoreHeader& h, const std::vector<int>& frames,
                                            const std::optional<AttributeRange>& range) {
  FLIPSCOPE_CHECK(h.attributeName.size() <= kMaxAttributeNameBytes, h.attributeName.size());
  FLIPSCOPE_CHECK(!h.particleKinds || h.version >= 5, "particle kinds in a version " << h.version << " store");
  FLIPSCOPE_CHECK(h.upAxis == UpAxis::Unknown || h.version >= 6, "an up axis in a version " << h.version << " store");
  const bool v3 = h.version == 3;
  ByteWriter w;
  w.append(kStoreMagic, sizeof kStoreMagic);
  w.put(h.version);
  w.put(h.brickSize);
  w.put(h.cellSize);
  w.put(h.origin.x);
  w.put(h.origin.y);
  w.put(h.origin.z);
  w.put(h.brickGrid.x);
  w.put(h.brickGrid.y);
  w.put(h.brickGrid.z);
  w.put(static_cast<std::uint32_t>(h.attribute));
  w.put(h.particleSpacing);
  w.append(h.id.data(), h.id.size());
  if (!v3) {
    w.put(std::uint32_t(h.attributeName.size()));
    w.append(h.attributeName.data(), h.attributeName.size());
    w.put(std::uint32_t(range ? 1 : 0));
    w.put(range ? range->min : 0.0f);
    w.put(range ? range->max : 0.0f);
  }
  if (h.version >= 5) w.put(std::uint32_t(h.particleKinds ? 1 : 0));
  if (h.version >= 6) w.put(static_cast<std::uint32_t>(h.upAxis));
  const auto runs = runsOf(frames);
  w.put(std::uint32_t(runs.size()));
  for (const FrameRun& run : runs) {
    w.put(run.first);
    w.put(run.count);
  }
  w.put(checksum64(w.view()));
  FLIPSCOPE_CHECK(w.size() == kStoreHeaderFixedBytes + (v3 ? 0 : kStoreHeaderV4Bytes + h.attributeName.size()) +
                                  (h.version >= 5 ? kStoreHeaderV5Bytes : 0) +
                                  (h.version >= 6 ? kStoreHeaderV6Bytes : 0) + 8 * runs.size() + 8,
                  w.size());
  return std::move(w.bytes());
}

StoreHeader parseStoreHeader(std::span<const std::byte> bytes, const std::filesystem::path& file,
                             std::vector<int>* frames, std::optional<AttributeRange>* rangeOut) {
  ByteReader r(bytes, file);
  auto magic = r.getBytes(8, "magic");
  if (std::memcmp(magic.data(), kStoreMagic, 8) != 0) r.fail("magic", "not a flipscope store header");
  StoreHeader h;
  h.version = r.get<std::uint32_t>("version");
  if (h.version < kOldestStoreVersion || h.version > kStoreVersion)
    r.fail("version", "unsupported store version " + std::to_string(h.version) + " (this flipscope reads versions " +
                          std::to_string(kOldestStoreVersion) + " to " + std::to_string(kStoreVersion) +
                          "); convert the particle files again into a new store");
  h.brickSize = r.get<std::uint32_t>("brick size");
  h.cellSize = r.get<double>("cell size");
  h.origin.x = r.get<double>("origin x");
  h.origin.y = r.get<double>("origin y");
  h.origin.z = r.get<double>("origin z");
  h.brickGrid.x = r.get<std::uint32_t>("brick grid x");
  h.brickGrid.y = r.get<std::uint32_t>("brick grid y");
  h.brickGrid.z = r.get<std::uint32_t>("brick grid z");
  auto attribute = r.get<std::uint32_t>("attribute");
  h.particleSpacing = r.get<double>("particle spacing");
  auto id = r.getBytes(h.id.size(), "store id");
  std::memcpy(h.id.data(), id.data(), h.id.size());
  std::optional<AttributeRange> range;
  if (h.version >= 4) {
    const auto length = r.get<std::uint32_t>("attribute name length");
    if (length > kMaxAttributeNameBytes)
      r.fail("attribute name length", "longer than " + std::to_string(kMaxAttributeNameBytes));
    auto name = r.getBytes(length, "attribute name");
    h.attributeName.assign(reinterpret_cast<const char*>(name.data()), name.size());
    const auto hasRange = r.get<std::uint32_t>("attribute range flag");
    AttributeRange values;
    values.min = r.get<float>("attribute range min");
    values.max = r.get<float>("attribute range max");
    if (hasRange > 1) r.fail("attribute range flag", "neither 0 nor 1");
    if (hasRange) range = values;
  }
  if (h.version >= 5) {
    const auto kinds = r.get<std::uint32_t>("particle kinds flag");
    if (kinds > 1) r.fail("particle kinds flag", "neither 0 nor 1");
    h.particleKinds = kinds == 1;
  }
  if (h.version >= 6) {
    const auto up = r.get<std::uint32_t>("up axis");
    if (up > static_cast<std::uint32_t>(UpAxis::Z)) r.fail("up axis", "unknown up axis " + std::to_string(up));
    h.upAxis = UpAxis(up);
  }
  const auto runCount = r.get<std::uint32_t>("frame table runs");
  if (runCount > r.remaining() / 8) r.fail("frame table runs", "more runs than the file holds");
  std::vector<FrameRun> runs(runCount);
  for (auto& run : runs) {
    run.first = r.get<std::int32_t>("frame run first");
    run.count = r.get<std::uint32_t>("frame run count");
  }
  const std::size_t checked = r.position();
  auto stored = r.get<std::uint64_t>("checksum");
  r.expectEnd("end of store header");
  if (stored != checksum64(bytes.first(checked))) throw FileError(file, "header checksum mismatch (file corrupted)");
  if (!isValidBrickSize(h.brickSize)) throw FileError(file, "invalid brick size " + std::to_string(h.brickSize));
  if (!(std::isfinite(h.cellSize) && h.cellSize > 0)) throw FileError(file, "invalid cell size");
  if (!std::isfinite(h.origin.x) || !std::isfinite(h.origin.y) || !std::isfinite(h.origin.z))
    throw FileError(file, "invalid origin");
  for (int a = 0; a < 3; ++a)
    if (h.brickGrid[a] == 0 || std::uint64_t(h.brickGrid[a]) * h.brickSize > 65536)
      throw FileError(file, "invalid brick grid");
  if (attribute > (h.version >= 4 ? 3u : 1u))
    throw FileError(file, "unknown attribute kind " + std::to_string(attribute));
  if (h.version == 3 && attribute == 1) h.attributeName = "speed";
  if ((attribute == 0) != h.attributeName.empty() || (attribute == 1 && h.attributeName != "speed"))
    throw FileError(file, "attribute name '" + h.attributeName.substr(0, 64) + "' does not fit attribute kind " +
                              std::to_string(attribute));
  for (char c : h.attributeName)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      throw FileError(file, "attribute name has a control character");
  if (range && (!std::isfinite(range->min) || !std::isfinite(range->max) || range->min > range->max || attribute == 0))
    throw FileError(file, "invalid attribute range");
  if (!(std::isfinite(h.particleSpacing) && h.particleSpacing >= 0)) throw FileError(file, "invalid particle spacing");
  h.attribute = AttributeKind(attribute);
  // Canonical runs: ascending, separated by a gap, within 0..kMaxFrame.
  std::int64_t previousEnd = -2;  // one past the last frame of the previous run
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const std::int64_t first = runs[i].first, end = first + std::int64_t(runs[i].count);
    if (runs[i].count == 0 || first < 0 || end - 1 > kMaxFrame || first <= previousEnd)
      throw FileError(file, "frame table run " + std::to_string(i) + " (frames " + std::to_string(first) + " to " +
                                std::to_string(end - 1) + ") is invalid or out of order");
    previousEnd = end;
  }
  if (frames) {
    frames->clear();
    for (const FrameRun& run : runs)
      for (std::uint32_t k = 0; k < run.count; ++k) frames->push_back(run.first + int(k));
  }
  if (rangeOut) *rangeOut = range;
  return h;
}

// ---- frame files -------------------------------------------------------------------------

FrameWriter::FrameWriter(const std::filesystem::path& file, const StoreHeader& header, int frame)
    : mHeader(header), mFrame(frame), mFile(file) {
  mFile.write(kFrameMagic, sizeof kFrameMagic);
}

void FrameWriter::addBrick(glm::uvec3 coord, std::uint32_t particles, std::uint32_t cells,
                           std::span<const std::byte> payload) {
  const std::uint32_t code = mortonEncode3(coord.x, coord.y, coord.z);
  FLIPSCOPE_CHECK(mCodes.empty() || code > mCodes.back(), "bricks out of Morton order");
  BrickRecord r;
  r.coord = coord;
  r.particles = particles;
  r.cells = cells;
  r.bytes = std::uint32_t(payload.size());
  r.offset = mFile.offset();
  r.checksum = checksum64(payload);
  mFile.write(payload);
  mRecords.push_back(r);
  mCodes.push_back(code);
}

FrameIndex FrameWriter::finish(const FrameStats& stats) {
  const std::uint32_t maxBricks = std::max({mHeader.brickGrid.x, mHeader.brickGrid.y, mHeader.brickGrid.z});
  FrameIndex index;
  index.frame = mFrame;
  index.file = mFile.destination();
  index.stats = stats;
  index.octree = PresenceOctree::build(mCodes, maxBricks);
  index.bricks = std::move(mRecords);

  FrameFooter footer;
  footer.octreeLevels = index.octree.levels;
  footer.nodeCount = std::uint32_t(index.octree.nodes.size());
  footer.brickCount = std::uint32_t(index.bricks.size());
  footer.frame = mFrame;
  footer.stats = stats;
  footer.storeId = mHeader.id;
  footer.version = mHeader.version;
  footer.octreeOffset = mFile.offset();
  footer.tableOffset = footer.octreeOffset + 8ull * footer.nodeCount;
  ByteWriter w;
  w.putArray(std::span<const OctreeNode>(index.octree.nodes));
  for (const auto& r : index.bricks) serializeRecord(w, r);
  serializeFooter(w, footer);
  w.put(checksum64(w.view()));
  w.append(kFooterMagic, sizeof kFooterMagic);
  mFile.write(w.view());
  index.fileBytes = mFile.offset();
  mFile.commit();
  return index;
}

FrameIndex readFrameIndex(const std::filesystem::path& file, const StoreHeader& header) {
  FileHandle handle(file);
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(file, ec);
  if (ec) throw FileError(file, "cannot stat: " + ec.message());
  if (size < sizeof kFrameMagic + kFrameFooterBytes)
    throw FileError(file, "truncated: " + std::to_string(size) + " bytes, smaller than an empty frame");
  char magic[8];
  readAt(handle.fd(), file, 0, magic, 8, "frame magic");
  if (std::memcmp(magic, kFrameMagic, 8) != 0) throw FileError(file, "at byte 0 (magic): not a flipscope frame file");

  // The smallest footer first: its magic, and the version at the place every version keeps it
  // (an old frame is named as one); then the footer of that version.
  std::vector<std::byte> footerBytes(kFrameFooterBytes);
  std::uint64_t footerOffset = size - kFrameFooterBytes;
  readAt(handle.fd(), file, footerOffset, footerBytes.data(), footerBytes.size(), "footer");
  if (std::memcmp(footerBytes.data() + kFrameFooterBytes - 8, kFooterMagic, 8) != 0)
    throw FileError(file, "no frame footer at byte " + std::to_string(footerOffset) +
                              " (file truncated or corrupted)");
  std::uint32_t version = 0;
  std::memcpy(&version, footerBytes.data() + kFrameFooterBytes - kFooterVersionFromEnd, 4);
  if (version != header.version)
    throw FileError(file, "unsupported frame version " + std::to_string(version) + " (the store is version " +
                              std::to_string(header.version) + ", this flipscope reads versions " +
                              std::to_string(kOldestStoreVersion) + " to " + std::to_string(kStoreVersion) +
                              "); convert the particle files again into a new store");
  const std::uint64_t footerSize = frameFooterBytes(version);
  if (size < sizeof kFrameMagic + footerSize)
    throw FileError(file, "truncated: " + std::to_string(size) + " bytes, smaller than an empty frame of version " +
                              std::to_string(version));
  if (footerSize != kFrameFooterBytes) {
    footerBytes.resize(footerSize);
    footerOffset = size - footerSize;
    readAt(handle.fd(), file, footerOffset, footerBytes.data(), footerBytes.size(), "footer");
  }
  ByteReader fr(std::span<const std::byte>(footerBytes).first(footerSize - 8), file, footerOffset);
  FrameFooter footer = parseFooter(fr, version);
  // The index region runs from the octree to the checksum field; check sizes before reading.
  const std::uint64_t nodesBytes = 8ull * footer.nodeCount;
  const std::uint64_t tableBytes = 40ull * footer.brickCount;
  if (footer.octreeOffset < sizeof kFrameMagic || footer.tableOffset != footer.octreeOffset + nodesBytes ||
      footer.tableOffset + tableBytes != footerOffset)
    throw FileError(file, "footer offsets inconsistent with the file size (file truncated or corrupted)");
  std::vector<std::byte> index(nodesBytes + tableBytes + footerSize - 16);
  readAt(handle.fd(), file, footer.octreeOffset, index.data(), index.size(), "octree and brick table");
  if (checksum64(index) != footer.indexChecksum)
    throw FileError(file, "index checksum mismatch: octree, brick table or footer corrupted");
  if (footer.storeId != header.id)
    throw FileError(file, "belongs to another store (its store id is " + storeIdText(footer.storeId) +
                              ", this store's is " + storeIdText(header.id) + "); frames cannot move between stores");

  FrameIndex out;
  out.file = file;
  out.fileBytes = size;
  out.frame = footer.frame;
  out.stats = footer.stats;
  out.octree.levels = footer.octreeLevels;
  out.octree.nodes.resize(footer.nodeCount);
  ByteReader r(std::span<const std::byte>(index).first(nodesBytes + tableBytes), file, footer.octreeOffset);
  r.getArray(std::span(out.octree.nodes), "octree");
  out.bricks.resize(footer.brickCount);
  std::vector<std::uint32_t> codes;
  codes.reserve(footer.brickCount);
  std::uint64_t expectedOffset = sizeof kFrameMagic, particles = 0, cells = 0;
  for (std::uint32_t i = 0; i < footer.brickCount; ++i) {
    BrickRecord& b = out.bricks[i];
    b.coord.x = r.get<std::uint32_t>("brick x");
    b.coord.y = r.get<std::uint32_t>("brick y");
    b.coord.z = r.get<std::uint32_t>("brick z");
    b.particles = r.get<std::uint32_t>("brick particles");
    b.cells = r.get<std::uint32_t>("brick cells");
    b.bytes = r.get<std::uint32_t>("brick bytes");
    b.offset = r.get<std::uint64_t>("brick offset");
    b.checksum = r.get<std::uint64_t>("brick checksum");
    const std::string which = "brick " + std::to_string(i);
    if (b.coord.x >= header.brickGrid.x || b.coord.y >= header.brickGrid.y || b.coord.z >= header.brickGrid.z)
      throw FileError(file, which + ": coordinates outside the brick grid");
    if (b.offset != expectedOffset || b.bytes == 0)
      throw FileError(file, which + ": payload range does not follow the previous brick");
    if (b.cells == 0 || b.cells > header.cellsPerBrick() || b.particles < b.cells)
      throw FileError(file, which + ": invalid particle or cell count");
    expectedOffset += b.bytes;
    particles += b.particles;
    cells += b.cells;
    const std::uint32_t code = mortonEncode3(b.coord.x, b.coord.y, b.coord.z);
    if (!codes.empty() && code <= codes.back()) throw FileError(file, which + ": bricks out of Morton order");
    codes.push_back(code);
  }
  if (expectedOffset != footer.octreeOffset) throw FileError(file, "brick payloads do not end where the octree starts");
  if (particles != footer.stats.particles) throw FileError(file, "brick particle counts do not add up to the total");
  std::uint64_t kindCells = 0;
  for (std::uint64_t n : footer.stats.kindCells) kindCells += n;
  if (kindCells != (header.particleKinds ? cells : 0))
    throw FileError(file, header.particleKinds ? "the cells of each particle kind do not add up to the bricks' cells"
                                               : "cells of particle kinds in a store without particle kinds");
  const std::uint32_t maxBricks = std::max({header.brickGrid.x, header.brickGrid.y, header.brickGrid.z});
  if (footer.octreeLevels != octreeLevelsFor(maxBricks) ||
      PresenceOctree::build(codes, maxBricks).nodes != out.octree.nodes)
    throw FileError(file, "presence octree does not match the brick table");
  return out;
}

// ---- BrickStore --------------------------------------------------------------------------

struct BrickStore::Shared {
  std::mutex mutex;
  std::set<int> frames;  ///< the frame table
  std::map<int, std::shared_ptr<const FrameIndex>> indices;
  std::optional<AttributeRange> range;  ///< version 4: as store.fsh records it
};

namespace {
/// `range` widened by the attribute range of `stats` (a frame with particles).
std::optional<AttributeRange> widened(std::optional<AttributeRange> range, const FrameStats& stats) {
  if (stats.particles == 0 || !std::isfinite(stats.attributeMin) || !std::isfinite(stats.attributeMax) ||
      stats.attributeMin > stats.attributeMax)
    return range;
  if (!range) return AttributeRange{stats.attributeMin, stats.attributeMax};
  return AttributeRange{std::min(range->min, stats.attributeMin), std::max(range->max, stats.attributeMax)};
}
}  // namespace

bool BrickStore::exists(const std::filesystem::path& dir) {
  std::error_code ec;
  return std::filesystem::exists(dir / kStoreHeaderName, ec);
}

BrickStore BrickStore::open(const std::filesystem::path& dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) throw FileError(dir, "not a brick store directory");
  const auto headerPath = dir / kStoreHeaderName;
  if (!std::filesystem::exists(headerPath, ec))
    throw FileError(dir, std::string("not a brick store: ") + kStoreHeaderName + " missing");
  BrickStore store;
  store.mDir = dir;
  std::vector<int> frames;
  std::optional<AttributeRange> range;
  store.mHeader = parseStoreHeader(readFile(headerPath), headerPath, &frames, &range);
  store.mShared = std::make_shared<Shared>();
  store.mShared->frames.insert(frames.begin(), frames.end());
  store.mShared->range = range;
  return store;
}

BrickStore BrickStore::createOrAppend(const std::filesystem::path& dir, const StoreHeader& header,
                                      FramelessStore frameless, bool* wrote) {
  if (wrote) *wrote = false;
  std::error_code created;
  std::filesystem::create_directories(dir, created);
  if (created) throw OutputError(dir, "cannot create the store directory: " + created.message());
  const StoreTableLock table(dir);  // two writers creating one store agree on one header
  if (exists(dir)) {
    BrickStore store = open(dir);
    if (!store.incomplete() || frameless == FramelessStore::Join) {
      const StoreHeader& h = store.header();
      if (h.brickSize != header.brickSize || h.cellSize != header.cellSize || h.origin != header.origin ||
          h.brickGrid != header.brickGrid || h.attribute != header.attribute || h.attributeName != header.attributeName)
        throw FileError(dir, store.incomplete()
                                 ? "another convert is creating this store with a different domain, cell size, "
                                   "brick size or attribute"
                                 : "existing store has a different domain, cell size, brick size or attribute");
      if (h.particleKinds != header.particleKinds) {
        const std::string theirs = h.particleKinds ? "has particle kinds" : "has no particle kinds";
        const std::string ours = header.particleKinds ? "with particle kinds" : "without particle kinds";
        throw FileError(dir, (store.incomplete() ? "another convert is creating this store, which " : "existing store ") +
                                 theirs + ", but this one writes frames " + ours);
      }
      return store;
    }
  }
  StoreHeader fresh = header;
  fresh.version = kStoreVersion;
  if (fresh.id == StoreId{}) fresh.id = randomStoreId();
  writeFileAtomically(dir / kStoreHeaderName, serializeStoreHeader(fresh));
  if (wrote) *wrote = true;
  return open(dir);
}

bool BrickStore::removeIfFrameless(const std::filesystem::path& dir, const StoreId& id) {
  const StoreTableLock table(dir);
  const auto headerPath = dir / kStoreHeaderName;
  std::error_code ec;
  if (!std::filesystem::exists(headerPath, ec)) return false;
  std::vector<int> frames;
  const StoreHeader now = parseStoreHeader(readFile(headerPath), headerPath, &frames);
  if (now.id != id || !frames.empty()) return false;  // another store now, or frames listed
  return std::filesystem::remove(headerPath, ec);
}

bool BrickStore::reloadFrameTable() {
  const auto headerPath = mDir / kStoreHeaderName;
  std::vector<int> onDisk;
  std::optional<AttributeRange> range;
  const StoreHeader now = parseStoreHeader(readFile(headerPath), headerPath, &onDisk, &range);
  if (now.id != mHeader.id)
    throw FileError(headerPath, "is now the header of another store (store " + storeIdText(now.id) + ", not " +
                                    storeIdText(mHeader.id) + "): it was converted anew; open it again");
  std::lock_guard lock(mShared->mutex);
  const std::size_t before = mShared->frames.size();
  mShared->frames.insert(onDisk.begin(), onDisk.end());
  if (range) mShared->range = range;
  return mShared->frames.size() != before;
}

std::vector<int> BrickStore::frames() const {
  std::lock_guard lock(mShared->mutex);
  return {mShared->frames.begin(), mShared->frames.end()};
}

bool BrickStore::hasFrame(int frame) const {
  std::lock_guard lock(mShared->mutex);
  return mShared->frames.count(frame) != 0;
}

std::filesystem::path BrickStore::framePath(int frame) const { return mDir / frameFileName(frame); }

std::vector<int> BrickStore::missingFrames() const {
  std::vector<int> missing;
  for (int f : frames())
    if (!missingFrameReason(f).empty()) missing.push_back(f);
  return missing;
}

std::string BrickStore::missingFrameReason(int frame) const {
  std::error_code ec;
  const auto status = std::filesystem::status(framePath(frame), ec);
  if (std::filesystem::is_regular_file(status)) return {};
  const std::string listed = std::string("missing: ") + kStoreHeaderName + " lists frame " + std::to_string(frame);
  if (ec && ec != std::errc::no_such_file_or_directory)
    return listed + ", but its file cannot be looked at: " + ec.message();
  if (!std::filesystem::exists(status)) return listed + ", but its file is gone";
  return listed + ", but a " +
         std::string(std::filesystem::is_directory(status) ? "directory" : "file that is not a regular file") +
         " has its name";
}

std::vector<std::filesystem::path> BrickStore::unlistedFrameFiles() const {
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(mDir, ec)) {
    const auto frame = frameFromFileName(entry.path().filename().string());
    if (frame && !hasFrame(*frame)) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::optional<AttributeRange> BrickStore::attributeRange() const {
  if (mHeader.attribute == AttributeKind::None) return std::nullopt;
  if (mHeader.version >= 4) {
    std::lock_guard lock(mShared->mutex);
    return mShared->range;
  }
  std::optional<AttributeRange> range;
  for (int f : frames()) range = widened(range, frame(f)->stats);
  return range;
}

void BrickStore::addFrame(int frame, const FrameStats& stats) {
  FLIPSCOPE_CHECK(frame >= 0 && frame <= kMaxFrame, frame);
  std::lock_guard lock(mShared->mutex);
  mShared->indices.erase(frame);
  const StoreTableLock table(mDir);
  // Other writers may have listed frames since this store was opened: start from store.fsh as it
  // is now. (A writer whose first frame failed removes a store.fsh without frames; this one
  // writes it again, with the same id.)
  const auto headerPath = mDir / kStoreHeaderName;
  std::set<int> frames = mShared->frames;
  std::optional<AttributeRange> listedRange = mShared->range;
  bool listed = false;
  std::error_code ec;
  if (std::filesystem::exists(headerPath, ec)) {
    std::vector<int> onDisk;
    const StoreHeader now = parseStoreHeader(readFile(headerPath), headerPath, &onDisk, &listedRange);
    if (now.id != mHeader.id)
      throw FileError(headerPath, "is now the header of another store (store " + storeIdText(now.id) + ", not " +
                                      storeIdText(mHeader.id) +
                                      "): a convert started the store anew while this one wrote frame " +
                                      std::to_string(frame));
    frames = {onDisk.begin(), onDisk.end()};
    listed = frames.count(frame) != 0;
  }
  std::optional<AttributeRange> range = listedRange;
  if (mHeader.attribute != AttributeKind::None && mHeader.version >= 4) range = widened(range, stats);
  frames.insert(frame);
  if (!listed || range != listedRange)
    writeFileAtomically(headerPath, serializeStoreHeader(mHeader, serializeList(frames), range));
  mShared->frames.swap(frames);
  mShared->range = range;
}

std::shared_ptr<const FrameIndex> BrickStore::frame(int frame) const {
  {
    std::lock_guard lock(mShared->mutex);
    if (!mShared->frames.count(frame))
      throw InputError(mDir.string() + ": no frame " + std::to_string(frame) + " in the store");
    if (auto it = mShared->indices.find(frame); it != mShared->indices.end()) return it->second;
  }
  const auto path = framePath(frame);
  if (const std::string missing = missingFrameReason(frame); !missing.empty()) throw FileError(path, missing);
  auto index = std::make_shared<const FrameIndex>(readFrameIndex(path, mHeader));
  if (index->frame != frame) throw FileError(path, "footer names frame " + std::to_string(index->frame));
  std::lock_guard lock(mShared->mutex);
  return mShared->indices.emplace(frame, index).first->second;
}

UninitializedVector<std::byte> BrickStore::readPayload(const FrameIndex& frame, std::uint32_t brickIndex) const {
  FLIPSCOPE_CHECK(brickIndex < frame.bricks.size(), brickIndex << " of " << frame.bricks.size());
  const BrickRecord& b = frame.bricks[brickIndex];
  UninitializedVector<std::byte> payload(b.bytes);  // pread fills it: no memset first
  FileHandle handle(frame.file);
  readAt(handle.fd(), frame.file, b.offset, payload.data(), payload.size(), "brick payload");
  if (checksum64(payload) != b.checksum)
    throw FileError(frame.file, "brick " + std::to_string(brickIndex) + " at (" + std::to_string(b.coord.x) + "," +
                                    std::to_string(b.coord.y) + "," + std::to_string(b.coord.z) +
                                    "): checksum mismatch (payload corrupted)");
  return payload;
}

DecodedBrick BrickStore::readBrick(const FrameIndex& frame, std::uint32_t brickIndex, bool attributes) const {
  auto payload = readPayload(frame, brickIndex);
  return decodeBrick(payload, frame.file, brickIndex, frame.bricks[brickIndex], mHeader.cellsPerBrick(),
                     mHeader.attribute != AttributeKind::None, mHeader.particleKinds,
                     attributeCodingOf(mHeader.version), attributes);
}

}  // namespace flipscope
