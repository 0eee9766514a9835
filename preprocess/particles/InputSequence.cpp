// Frame patterns of `flipscope convert` inputs: `####` (zero padded to the run's width),
// printf `%d` / `%0Nd`, `{}`, and Houdini's `$F` / `$F4`; expansion into frames from a range or
// the directory listing.
#include "preprocess/particles/InputSequence.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <map>
#include <set>

#include "core/Error.h"
#include "preprocess/particles/ParticleFormatRegistry.h"

namespace flipscope {
namespace {

/// An input split around its frame number: prefix + number padded to `width` + suffix.
struct FramePattern {
  std::string prefix;
  std::string suffix;
  int width = 0;  ///< zero-padded width; 0 = unpadded
};

std::optional<FramePattern> findPattern(const std::string& input) {
  for (std::size_t i = 0; i < input.size(); ++i) {
    if (input[i] == '#') {
      std::size_t end = input.find_first_not_of('#', i);
      if (end == std::string::npos) end = input.size();
      return FramePattern{input.substr(0, i), input.substr(end), int(end - i)};
    }
    if (input.compare(i, 2, "{}") == 0) return FramePattern{input.substr(0, i), input.substr(i + 2), 0};
    // Houdini's $F (unpadded) and $F2 to $F9 (zero padded), as in `name.$F4.bgeo.sc`; not
    // $FF, $FPS, $FSTART and other variables that begin with F.
    if (input.compare(i, 2, "$F") == 0) {
      std::size_t j = i + 2;
      int width = 0;
      if (j < input.size() && input[j] >= '1' && input[j] <= '9') width = input[j++] - '0';
      if (j == input.size() || !std::isalnum(static_cast<unsigned char>(input[j])))
        return FramePattern{input.substr(0, i), input.substr(j), width};
    }
    if (input[i] == '%') {
      std::size_t j = i + 1;
      int width = 0;
      if (j < input.size() && input[j] == '0') {
        std::size_t digitsEnd = input.find_first_not_of("0123456789", j + 1);
        if (digitsEnd == std::string::npos || digitsEnd == j + 1) continue;
        std::from_chars(input.data() + j + 1, input.data() + digitsEnd, width);
        j = digitsEnd;
      }
      if (j < input.size() && input[j] == 'd') return FramePattern{input.substr(0, i), input.substr(j + 1), width};
    }
  }
  return std::nullopt;
}

std::string formatFrame(int frame, int width) {
  std::string digits = std::to_string(frame);
  if (int(digits.size()) < width) digits.insert(0, width - digits.size(), '0');
  return digits;
}

/// Frame numbers of the files in the pattern's directory that match it, sorted.
std::vector<int> discoverFrames(const std::string& input, const FramePattern& pattern) {
  if (pattern.suffix.find('/') != std::string::npos)
    throw InputError("input '" + input + "': a frame pattern in a directory name needs --frames");
  std::size_t slash = pattern.prefix.rfind('/');
  std::filesystem::path dir = slash == std::string::npos ? "." : pattern.prefix.substr(0, slash + 1);
  std::string namePrefix = slash == std::string::npos ? pattern.prefix : pattern.prefix.substr(slash + 1);
  std::error_code ec;
  std::filesystem::directory_iterator it(dir, ec);
  if (ec) throw FileError(dir, "cannot list the directory of input pattern '" + input + "': " + ec.message());
  std::set<int> frames;
  for (const auto& entry : it) {
    std::string name = entry.path().filename().string();
    if (name.size() <= namePrefix.size() + pattern.suffix.size() || name.rfind(namePrefix, 0) != 0 ||
        name.compare(name.size() - pattern.suffix.size(), pattern.suffix.size(), pattern.suffix) != 0)
      continue;
    std::string_view digits(name.data() + namePrefix.size(), name.size() - namePrefix.size() - pattern.suffix.size());
    int frame = 0;
    auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), frame);
    if (error != std::errc() || end != digits.data() + digits.size() || frame < 0) continue;
    if (formatFrame(frame, pattern.width) == digits) frames.insert(frame);
  }
  if (frames.empty()) throw FileError(dir, "no file matches input pattern '" + input + "'");
  return {frames.begin(), frames.end()};
}

/// The numbered particle files in `dir` and in its sub-directories one level down, as input
/// patterns (the number's last run of digits as '#', one per digit of the shortest) with how
/// many files each has, the most first, at most `limit`: "'dir/data/fluid_data_####.vdb' (30
/// files)". For the message of a directory given as an input.
std::vector<std::string> numberedSequencesIn(const std::filesystem::path& dir, std::size_t limit) {
  struct Group {
    std::size_t files = 0, digits = 0;
  };
  std::map<std::pair<std::filesystem::path, std::string>, Group> groups;  // (directory, name with '#')
  constexpr std::size_t kMaxEntries = 100000;                             // a listing that large is not worth the wait
  std::size_t entries = 0;
  // Lists `folder`; its sub-directories go to `subfolders` where given.
  const auto scan = [&](const std::filesystem::path& folder, std::vector<std::filesystem::path>* subfolders) {
    std::error_code ec;
    for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end && entries < kMaxEntries;
         it.increment(ec), ++entries) {
      const std::string name = it->path().filename().string();
      std::error_code typeError;
      if (subfolders && it->is_directory(typeError)) {
        subfolders->push_back(it->path());
        continue;
      }
      const std::size_t stem = name.size() - particleExtensionLength(name);
      if (stem == name.size() || stem == 0) continue;  // not a particle file, or no more than its extension
      const std::size_t last = name.find_last_of("0123456789", stem - 1);
      if (last == std::string::npos) continue;
      const std::size_t first = name.find_last_not_of("0123456789", last) + 1;  // npos + 1 = 0
      Group& group = groups[{folder, name.substr(0, first) + '#' + name.substr(last + 1)}];
      const std::size_t digits = last + 1 - first;
      group.digits = group.files++ ? std::min(group.digits, digits) : digits;
    }
  };
  std::vector<std::filesystem::path> subfolders;
  scan(dir, &subfolders);
  for (const std::filesystem::path& folder : subfolders) scan(folder, nullptr);
  std::vector<std::pair<std::size_t, std::string>> found;
  for (const auto& [key, group] : groups) {
    std::string name = key.second;
    name.replace(name.find('#'), 1, std::string(group.digits, '#'));
    found.emplace_back(group.files, "'" + (key.first / name).string() + "' (" + std::to_string(group.files) +
                                        (group.files == 1 ? " file)" : " files)"));
  }
  std::stable_sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<std::string> result;
  for (std::size_t i = 0; i < found.size() && i < limit; ++i) result.push_back(found[i].second);
  return result;
}

void expectFile(const std::filesystem::path& path, const std::string& context) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw FileError(path, "no such file (" + context + ")");
  if (std::filesystem::is_directory(status)) {
    std::string holds;
    for (const std::string& sequence : numberedSequencesIn(path, 6)) holds += (holds.empty() ? "" : ", ") + sequence;
    throw FileError(path, "is a directory, expected a particle file or a frame pattern (" + context + "); " +
                              (holds.empty() ? "it holds no numbered particle files"
                                             : "it holds the numbered particle files " + holds));
  }
  if (!std::filesystem::is_regular_file(status))
    throw FileError(path, "is not a regular file (a device, pipe or socket), expected a particle file (" + context + ")");
}

}  // namespace

FrameRange parseFrameRange(const std::string& text) {
  auto parse = [&](std::string_view part) {
    int value = 0;
    auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), value);
    if (part.empty() || ec != std::errc() || end != part.data() + part.size() || value < 0)
      throw InputError("bad frame range '" + text + "' (expected A-B or A, frame numbers >= 0)");
    return value;
  };
  std::size_t dash = text.find('-');
  FrameRange range;
  if (dash == std::string::npos) {
    range.first = range.last = parse(text);
  } else {
    range.first = parse(std::string_view(text).substr(0, dash));
    range.last = parse(std::string_view(text).substr(dash + 1));
  }
  if (range.last < range.first) throw InputError("bad frame range '" + text + "': last frame before first");
  return range;
}

std::string substituteFrame(const std::string& pattern, int frame) {
  auto split = findPattern(pattern);
  if (!split) return pattern;
  return split->prefix + formatFrame(frame, split->width) + split->suffix;
}

bool hasFramePattern(const std::string& input) { return findPattern(input).has_value(); }

int firstFrameOf(const std::vector<std::string>& inputs) {
  const auto firstPattern = std::find_if(inputs.begin(), inputs.end(), hasFramePattern);
  if (firstPattern == inputs.end()) return 0;
  return discoverFrames(*firstPattern, *findPattern(*firstPattern)).front();
}

bool isStoreDirectory(const std::vector<std::string>& inputs) {
  return inputs.size() == 1 && std::filesystem::is_directory(inputs.front());
}

std::vector<FrameInput> expandInputs(const std::vector<std::string>& inputs, std::optional<FrameRange> frames) {
  if (inputs.empty()) throw InputError("no input files");
  auto firstPattern = std::find_if(inputs.begin(), inputs.end(), hasFramePattern);
  std::vector<int> numbers;
  if (firstPattern == inputs.end()) {
    numbers.push_back(frames ? frames->first : 0);
  } else if (frames) {
    for (int f = frames->first; f <= frames->last; ++f) numbers.push_back(f);
  } else {
    numbers = discoverFrames(*firstPattern, *findPattern(*firstPattern));
  }
  std::vector<FrameInput> result;
  for (int frame : numbers) {
    FrameInput input{frame, {}};
    for (const auto& name : inputs) {
      bool patterned = hasFramePattern(name);
      input.files.emplace_back(substituteFrame(name, frame));
      expectFile(input.files.back(),
                 patterned ? "frame " + std::to_string(frame) + " of input pattern '" + name + "'" : "input file");
    }
    result.push_back(std::move(input));
  }
  return result;
}

}  // namespace flipscope
