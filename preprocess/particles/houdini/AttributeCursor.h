// AttributeCursor: reads the values of one Houdini point attribute in point order, a chunk at a
// time, from where the scan found them (GeoScan.h). Houdini stores attribute after attribute,
// so the reader keeps one cursor an attribute (each with its own buffer) to hand out P, v and
// the other attributes of the same points together.
// Memory: the cursor's read buffer, and for paged storage one page (pagesize * arity floats).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/houdini/GeoScan.h"
#include "preprocess/particles/houdini/JsonReader.h"

namespace flipscope::detail::houdini {

class AttributeCursor {
 public:
  /// Reads `attribute` of `file` (which, like `attribute`, must outlive the cursor).
  AttributeCursor(InputFile& file, JsonEncoding encoding, const PointAttribute& attribute, std::uint64_t points);

  /// Starts over from the first point.
  void rewind();
  /// The values of the next `count` points, `arity` floats a point, point after point.
  void read(float* out, std::size_t count);

 private:
  void loadPage();

  const PointAttribute* mAttribute;
  std::uint64_t mPoints;
  std::size_t mArity;
  std::vector<JsonReader> mReaders;  ///< one; Arrays: one a component
  std::vector<NumberArray> mArrays;  ///< the arrays the readers are in (Paged, Arrays)
  std::uint64_t mNext = 0;           ///< next point
  // Paged storage.
  std::uint64_t mPage = 0;       ///< next page to load
  std::vector<float> mPageValues;  ///< the loaded page, arity floats a point
  std::size_t mPagePoints = 0;   ///< points in the loaded page
  std::size_t mPagePos = 0;      ///< next point of the loaded page
  bool mPlainPages = false;      ///< one subvector, no constant pages: the values read straight through
  std::vector<float> mScratch;
  std::string mWhatPages, mWhatTuple, mWhatArray;  ///< for messages
};

}  // namespace flipscope::detail::houdini
