// AttributeCursor: see AttributeCursor.h. Paged storage ("rawpagedata", GA_PageArray of the HDK)
// holds page after page; a page holds each packed subvector in turn, either `points * size`
// numbers (point after point) or, when the page is constant for that subvector, one tuple of
// `size` numbers for all its points.
#include "preprocess/particles/houdini/AttributeCursor.h"

#include <algorithm>
#include <cstring>

#include "core/Error.h"

namespace flipscope::detail::houdini {
namespace {
constexpr std::size_t kCursorBufferBytes = std::size_t(1) << 18;
constexpr std::size_t kMinCursorBufferBytes = std::size_t(1) << 14;
}

AttributeCursor::AttributeCursor(InputFile& file, JsonEncoding encoding, const PointAttribute& attribute,
                                 std::uint64_t points)
    : mAttribute(&attribute),
      mPoints(points),
      mArity(std::size_t(attribute.arity)),
      mWhatPages("point attribute '" + attribute.name + "' rawpagedata"),
      mWhatTuple("point attribute '" + attribute.name + "' tuple"),
      mWhatArray("point attribute '" + attribute.name + "' array") {
  // One buffer, or a share of it a component ("arrays").
  const std::size_t readers = std::max<std::size_t>(1, attribute.dataOffsets.size());
  const std::size_t bufferBytes = std::max(kCursorBufferBytes / readers, kMinCursorBufferBytes);
  for (std::size_t i = 0; i < attribute.dataOffsets.size(); ++i)
    mReaders.emplace_back(file, encoding, attribute.dataOffsets[i], bufferBytes);
  if (attribute.layout == ValueLayout::Paged) {
    bool constant = false;
    for (const auto& flags : attribute.constantPages)
      constant = constant || std::find(flags.begin(), flags.end(), true) != flags.end();
    mPlainPages = attribute.packing.size() == 1 && !constant;
  }
  rewind();
}


void AttributeCursor::rewind() {
  mNext = 0;
  mPage = 0;
  mPagePoints = mPagePos = 0;
  mArrays.clear();
  if (mPoints == 0) return;
  for (std::size_t i = 0; i < mReaders.size(); ++i) {
    mReaders[i].seek(mAttribute->dataOffsets[i]);
    if (mAttribute->layout == ValueLayout::Tuples)
      mReaders[i].beginArray(mWhatTuple + "s");
    else
      mArrays.push_back(mReaders[i].beginNumbers(mWhatArray));
  }
}

void AttributeCursor::loadPage() {
  const PointAttribute& a = *mAttribute;
  const std::uint64_t first = mPage * a.pageSize;
  const std::size_t points = std::size_t(std::min<std::uint64_t>(a.pageSize, mPoints - first));
  mPageValues.resize(points * mArity);
  JsonReader& in = mReaders[0];
  NumberArray& array = mArrays[0];
  std::size_t component = 0;
  for (std::size_t j = 0; j < a.packing.size(); ++j) {
    const auto size = std::size_t(a.packing[j]);
    const auto& flags = a.constantPages[j];
    if (!flags.empty() && flags[mPage]) {
      float tuple[kMaxArity];
      in.readNumbers(array, tuple, size, mWhatPages);
      for (std::size_t p = 0; p < points; ++p)
        std::memcpy(mPageValues.data() + p * mArity + component, tuple, size * sizeof(float));
    } else if (size == mArity) {
      in.readNumbers(array, mPageValues.data(), points * size, mWhatPages);
    } else {
      mScratch.resize(points * size);
      in.readNumbers(array, mScratch.data(), points * size, mWhatPages);
      for (std::size_t p = 0; p < points; ++p)
        std::memcpy(mPageValues.data() + p * mArity + component, mScratch.data() + p * size, size * sizeof(float));
    }
    component += size;
  }
  mPagePoints = points;
  mPagePos = 0;
  ++mPage;
}

void AttributeCursor::read(float* out, std::size_t count) {
  FLIPSCOPE_CHECK(mNext + count <= mPoints, "next=" << mNext << " count=" << count << " points=" << mPoints);
  const PointAttribute& a = *mAttribute;
  switch (a.layout) {
    case ValueLayout::Paged:
      if (mPlainPages) {  // the pages follow each other without gaps: point after point
        mReaders[0].readNumbers(mArrays[0], out, count * mArity, mWhatPages);
        mNext += count;
        break;
      }
      while (count > 0) {
        if (mPagePos == mPagePoints) {
          loadPage();
        }
        const std::size_t n = std::min(count, mPagePoints - mPagePos);
        std::memcpy(out, mPageValues.data() + mPagePos * mArity, n * mArity * sizeof(float));
        mPagePos += n;
        out += n * mArity;
        count -= n;
        mNext += n;
      }
      break;
    case ValueLayout::Tuples:
      for (std::size_t p = 0; p < count; ++p) {
        NumberArray tuple = mReaders[0].beginNumbers(mWhatTuple);
        mReaders[0].readNumbers(tuple, out + p * mArity, mArity, mWhatTuple);
        mReaders[0].endNumbers(tuple, mWhatTuple);
      }
      mNext += count;
      break;
    case ValueLayout::Arrays:
      mScratch.resize(count);
      for (std::size_t c = 0; c < mArity; ++c) {
        mReaders[c].readNumbers(mArrays[c], mScratch.data(), count, mWhatArray);
        for (std::size_t p = 0; p < count; ++p) out[p * mArity + c] = mScratch[p];
      }
      mNext += count;
      break;
  }
}

}  // namespace flipscope::detail::houdini
