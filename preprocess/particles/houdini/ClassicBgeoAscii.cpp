// Houdini classic ASCII geometry ("PGEOMETRY V5", the text twin of BgeoV; ClassicBgeo.h), read
// as particles. The header is four lines of counts; the point dictionary follows the line
// "PointAttrib", one attribute a line ("Cd 3 float 1 1 1", "name 1 index 2 a b"); then one
// line a point: "x y z w", and the attribute values in parentheses when there are any:
// "0.1 0.2 0.3 1 (0.5 0.5 1)". Whatever follows the points (primitives, groups, detail
// attributes) is skipped line by line up to "endExtra", which must end the file: a file without
// it is truncated.
#include <algorithm>
#include <charconv>
#include <cstring>

#include "core/Error.h"
#include "preprocess/particles/BinaryColumns.h"
#include "preprocess/particles/InputFile.h"
#include "preprocess/particles/ParticleFormats.h"
#include "preprocess/particles/houdini/ClassicBgeo.h"

namespace flipscope::detail::houdini {
namespace {

constexpr std::size_t kMaxLineBytes = std::size_t(1) << 20;

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/// Whitespace-separated words of `text` (views into it).
void splitWords(std::string_view text, std::vector<std::string_view>& words) {
  words.clear();
  for (std::size_t i = 0; i < text.size();) {
    while (i < text.size() && isSpace(text[i])) ++i;
    const std::size_t start = i;
    while (i < text.size() && !isSpace(text[i])) ++i;
    if (i > start) words.push_back(text.substr(start, i - start));
  }
}

class ClassicGeoReader final : public ParticleSource {
 public:
  ClassicGeoReader(InputFile file, const ReadOptions& options) : mFile(std::move(file)) {
    std::vector<std::string_view> words;
    if (!nextLine(words) || words.size() != 2 || words[0] != "PGEOMETRY")
      throw FileError(mFile.path(), "bad magic: not a Houdini classic geo file (expected 'PGEOMETRY V5' on line 1)");
    if (words[1] != "V5") throw fail("version '" + std::string(words[1]) + "' (this reader reads PGEOMETRY V5)");
    readCounts(words);
    if (mCounts[4] > 0) {
      if (!nextLine(words)) throw fail("the file ends before the point attributes");
      if (words.size() != 1 || words[0] != "PointAttrib")
        throw fail("expected 'PointAttrib' (the header declares " + std::to_string(mCounts[4]) +
                   " point attributes), found '" + mLine + "'");
      for (std::uint64_t i = 0; i < mCounts[4]; ++i) readDefinition(words);
    }
    mValues = 0;
    for (auto& a : mPoint) {
      a.offset = mValues;
      mValues += std::size_t(a.size);
    }
    mPlan = planClassicAttributes(mPoint);
    mSelected = selectAttributes(mPlan.exposed, options, mFile.path());
    mColumns = makeColumns(mPlan.exposed, mSelected);
    mHasVelocity = options.velocity && mPlan.velocity.has_value();
    mDataOffset = mFile.offset();
    mDataLine = mLineNumber;
  }

  std::string name() const override { return mFile.path().string(); }
  std::string format() const override { return "Houdini classic ASCII geometry (PGEOMETRY V5)"; }
  /// Houdini's world is +y up.
  UpAxis upAxis() const override { return UpAxis::Y; }
  std::vector<AttributeDesc> attributes() const override { return mPlan.exposed; }
  bool hasVelocity() const override { return mHasVelocity; }
  std::optional<std::uint64_t> countHint() const override { return mCounts[0]; }

  bool read(ParticleChunk& chunk, std::size_t maxParticles) override {
    FLIPSCOPE_CHECK(maxParticles > 0);
    chunk.clear();
    const std::size_t n = std::size_t(std::min<std::uint64_t>(maxParticles, mCounts[0] - mNext));
    prepareColumns(chunk, mColumns, n);
    std::vector<std::string_view> words;
    if (n == 0) {
      if (!mTailChecked) checkTail(words);  // no points: what follows the header is all there is
      mTailChecked = true;
      return false;
    }
    chunk.positions.resize(n);
    if (mHasVelocity) chunk.velocities.resize(n);
    mRow.resize(mValues);
    for (std::size_t k = 0; k < n; ++k) {
      readPoint(words, mNext + k, chunk.positions[k]);
      if (mHasVelocity) {
        const float* v = mRow.data() + mPoint[*mPlan.velocity].offset;
        chunk.velocities[k] = {v[0], v[1], v[2]};
      }
      for (std::size_t c = 0; c < mSelected.size(); ++c) {
        const ClassicAttribute& a = mPoint[mPlan.exposedSource[mSelected[c]]];
        std::copy_n(mRow.data() + a.offset, a.size, chunk.attributes[c].values.data() + k * std::size_t(a.size));
      }
    }
    mNext += n;
    if (mNext == mCounts[0] && !mTailChecked) {
      checkTail(words);
      mTailChecked = true;
    }
    return true;
  }

  void rewind() override {
    mFile.seek(mDataOffset);
    mLineNumber = mDataLine;
    mNext = 0;
  }

 private:
  FileError fail(const std::string& what) const {
    return FileError(mFile.path(), "classic geo line " + std::to_string(mLineNumber) + ": " + what);
  }

  /// The next line that is not blank, split into words; false at the end of the file.
  bool nextLine(std::vector<std::string_view>& words) {
    while (mFile.readLine(mLine, kMaxLineBytes)) {
      ++mLineNumber;
      splitWords(mLine, words);
      if (!words.empty()) return true;
    }
    words.clear();
    return false;
  }

  template <class T>
  bool parse(std::string_view word, T& value) const {
    if (word.size() > 1 && word[0] == '+') word.remove_prefix(1);
    const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
    return ec == std::errc() && end == word.data() + word.size();
  }

  /// "NPoints 5 NPrims 1" ... until the eight counts are read.
  void readCounts(std::vector<std::string_view>& words) {
    static constexpr const char* kNames[8] = {"NPoints",      "NPrims",        "NPointGroups", "NPrimGroups",
                                              "NPointAttrib", "NVertexAttrib", "NPrimAttrib",  "NAttrib"};
    bool seen[8] = {};
    int found = 0;
    while (found < 8) {
      if (!nextLine(words)) throw fail("the file ends inside the header (" + std::to_string(found) + " of 8 counts)");
      if (words.size() % 2 != 0) throw fail("expected 'Name count' pairs in the header, found '" + mLine + "'");
      for (std::size_t w = 0; w < words.size(); w += 2) {
        const auto* name = std::find(std::begin(kNames), std::end(kNames), words[w]);
        if (name == std::end(kNames)) throw fail("unknown header field '" + std::string(words[w]) + "'");
        const std::size_t i = std::size_t(name - std::begin(kNames));
        if (seen[i]) throw fail("header field " + std::string(words[w]) + " given twice");
        if (!parse(words[w + 1], mCounts[i]) || mCounts[i] > (std::uint64_t(1) << 40))
          throw fail("malformed " + std::string(words[w]) + " '" + std::string(words[w + 1]) + "'");
        seen[i] = true;
        ++found;
      }
    }
  }

  /// One point attribute definition line: name size type defaults...
  void readDefinition(std::vector<std::string_view>& words) {
    if (!nextLine(words)) throw fail("the file ends inside the point attributes");
    if (words.size() < 3) throw fail("expected 'name size type defaults', found '" + mLine + "'");
    ClassicAttribute a;
    a.name = std::string(words[0]);
    if (!parse(words[1], a.size) || a.size < 1 || a.size > 65535)
      throw fail("point attribute '" + a.name + "' has a malformed size '" + std::string(words[1]) + "'");
    const std::string_view type = words[2];
    if (type == "float" || type == "int" || type == "vector") {
      a.type = type == "float" ? ClassicType::Float : type == "int" ? ClassicType::Int : ClassicType::Vector;
      if (words.size() != 3 + std::size_t(a.size))
        throw fail("point attribute '" + a.name + "' has " + std::to_string(words.size() - 3) +
                   " default values, expected " + std::to_string(a.size));
    } else if (type == "index") {
      a.type = ClassicType::Index;  // "index count string...": the strings are not needed
    } else {
      throw fail("point attribute '" + a.name + "' has type '" + std::string(type) +
                 "', which this reader cannot read (float, int, vector and index)");
    }
    mPoint.push_back(std::move(a));
  }

  /// Point `point`'s line into `position` and mRow.
  void readPoint(std::vector<std::string_view>& words, std::uint64_t point, glm::vec3& position) {
    if (!nextLine(words))
      throw fail("the file ends at point " + std::to_string(point) + " of " + std::to_string(mCounts[0]));
    if (!mFile.lineTerminated()) throw fail("the file ends inside a point line without a line break: truncated?");
    const std::size_t open = mLine.find('('), close = mLine.rfind(')');
    std::string_view coordinates = mLine, values;
    if (open != std::string::npos) {
      if (close == std::string::npos || close < open) throw fail("'(' without ')' in a point line");
      for (std::size_t i = close + 1; i < mLine.size(); ++i)
        if (!isSpace(mLine[i])) throw fail("unexpected text after ')' in a point line");
      coordinates = std::string_view(mLine).substr(0, open);
      values = std::string_view(mLine).substr(open + 1, close - open - 1);
    } else if (mValues > 0) {
      throw fail("expected the point's attribute values in parentheses");
    }
    splitWords(coordinates, words);
    if (words.size() != 4) throw fail("expected x y z w, found " + std::to_string(words.size()) + " values");
    for (int c = 0; c < 3; ++c) position[c] = number(words[std::size_t(c)], "a coordinate");
    (void)number(words[3], "w");
    splitWords(values, words);
    if (words.size() != mValues)
      throw fail("expected " + std::to_string(mValues) + " attribute values, found " + std::to_string(words.size()));
    for (std::size_t i = 0; i < mValues; ++i) mRow[i] = number(words[i], "an attribute value");
  }

  float number(std::string_view word, const char* what) const {
    double value = 0;
    if (!parse(word, value)) throw fail("malformed number '" + std::string(word) + "' for " + what);
    return static_cast<float>(value);
  }

  /// Primitives, groups and detail attributes: skipped up to "endExtra", which ends the file.
  void checkTail(std::vector<std::string_view>& words) {
    while (nextLine(words)) {
      if (words.size() == 1 && words[0] == "endExtra") {
        if (!mFile.lineTerminated()) throw fail("'endExtra' without a line break: truncated?");
        if (nextLine(words)) throw fail("text after 'endExtra', which ends the file: '" + mLine + "'");
        return;
      }
    }
    throw fail("the file ends before 'endExtra' (primitives, groups or detail attributes cut short): truncated?");
  }

  InputFile mFile;
  std::string mLine;
  std::uint64_t mLineNumber = 0;
  std::uint64_t mCounts[8] = {};
  std::vector<ClassicAttribute> mPoint;
  std::size_t mValues = 0;  ///< attribute values a point
  ClassicPlan mPlan;
  std::vector<std::size_t> mSelected;
  std::vector<AttributeColumn> mColumns;
  bool mHasVelocity = false;
  std::uint64_t mDataOffset = 0, mDataLine = 0;
  std::uint64_t mNext = 0;
  bool mTailChecked = false;
  std::vector<float> mRow;
};

}  // namespace

std::unique_ptr<ParticleSource> openClassicBgeoAscii(InputFile file, const ReadOptions& options) {
  return std::make_unique<ClassicGeoReader>(std::move(file), options);
}

}  // namespace flipscope::detail::houdini
