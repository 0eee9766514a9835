#include "gl/ShaderSource.h"

#include <set>
#include <stdexcept>

#include "flipscope_gl_embedded.h"

namespace flipscope::gl {

namespace {

namespace embedded = flipscope::embedded::flipscope_gl;

const embedded::TextFile* findFile(std::string_view name) {
  for (const embedded::TextFile& file : embedded::kFiles)
    if (file.name == name) return &file;
  return nullptr;
}

std::string_view trimLeft(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  return s;
}

/// The quoted name of an `#include "..."` line, or empty when the line is no include.
/// Throws for an #include without a quoted name.
std::string_view includedName(std::string_view line, std::string_view file) {
  std::string_view rest = trimLeft(line);
  if (!rest.starts_with('#')) return {};
  rest = trimLeft(rest.substr(1));
  if (!rest.starts_with("include")) return {};
  rest = trimLeft(rest.substr(7));
  const std::size_t close = rest.size() > 1 ? rest.find('"', 1) : std::string_view::npos;
  if (!rest.starts_with('"') || close == std::string_view::npos)
    throw std::runtime_error("shader " + std::string(file) + ": malformed include line: " + std::string(line));
  return rest.substr(1, close - 1);
}

void append(std::string& out, const embedded::TextFile& file, std::set<std::string_view>& pasted) {
  pasted.insert(file.name);
  std::string_view text = file.text;
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    const std::string_view line = text.substr(0, end);
    text = end == std::string_view::npos ? std::string_view() : text.substr(end + 1);
    const std::string_view include = includedName(line, file.name);
    if (include.empty()) {
      out.append(line);
      out += '\n';
      continue;
    }
    const std::size_t slash = include.find_last_of('/');
    const std::string_view base = slash == std::string_view::npos ? include : include.substr(slash + 1);
    const embedded::TextFile* included = findFile(base);
    if (!included)
      throw std::runtime_error("shader " + std::string(file.name) + ": unknown include \"" + std::string(include) +
                               "\" (not an embedded shader file)");
    if (pasted.count(included->name)) {
      out += "// (already included: " + std::string(base) + ")\n";
      continue;
    }
    out += "// ---- begin " + std::string(base) + " ----\n";
    append(out, *included, pasted);
    out += "// ---- end " + std::string(base) + " ----\n";
  }
}

}  // namespace

std::string shaderSource(std::string_view fileName, std::string_view defines) {
  const embedded::TextFile* file = findFile(fileName);
  if (!file) throw std::runtime_error("unknown shader file \"" + std::string(fileName) + "\" (not embedded)");
  std::string out = "#version 450 core\n#define FS_FUNC\n#define FS_INOUT(T) inout T\n";
  out.append(defines);
  if (!defines.empty() && defines.back() != '\n') out += '\n';
  std::set<std::string_view> pasted;
  append(out, *file, pasted);
  return out;
}

}  // namespace flipscope::gl
