// Attribute names and types shared by every reader (ParticleSource.h, ParticleFormats.h).
#include <algorithm>
#include <cctype>
#include <cstring>

#include "core/Error.h"
#include "preprocess/particles/ParticleFormats.h"
#include "preprocess/particles/ParticleSource.h"

namespace flipscope {

std::string_view valueTypeName(ValueType type) {
  switch (type) {
    case ValueType::Int8: return "int8";
    case ValueType::UInt8: return "uint8";
    case ValueType::Int16: return "int16";
    case ValueType::UInt16: return "uint16";
    case ValueType::Int32: return "int32";
    case ValueType::UInt32: return "uint32";
    case ValueType::Int64: return "int64";
    case ValueType::UInt64: return "uint64";
    case ValueType::Float16: return "float16";
    case ValueType::Float32: return "float32";
    case ValueType::Float64: return "float64";
  }
  return "unknown";
}

std::string detail::asciiLower(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = char(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::optional<std::size_t> detail::velocityAttributeByName(const std::vector<AttributeDesc>& attributes) {
  for (std::string_view name : {"velocity", "velocities", "vel", "v"})
    for (std::size_t i = 0; i < attributes.size(); ++i)
      if (attributes[i].arity == 3 && asciiLower(attributes[i].name) == name) return i;
  return std::nullopt;
}

std::vector<std::size_t> detail::selectAttributes(const std::vector<AttributeDesc>& available, const ReadOptions& options,
                                                  const std::filesystem::path& file) {
  std::vector<std::size_t> selected;
  if (options.allAttributes) {
    for (std::size_t i = 0; i < available.size(); ++i) selected.push_back(i);
    return selected;
  }
  for (const auto& name : options.attributes) {
    auto found = std::find_if(available.begin(), available.end(), [&](const AttributeDesc& a) { return a.name == name; });
    if (found == available.end()) {
      std::string names;
      for (const auto& a : available) names += (names.empty() ? "" : ", ") + a.name;
      throw FileError(file, "has no attribute '" + name + "' (" +
                                (names.empty() ? std::string("it holds positions only") : "it holds: " + names) + ")");
    }
    selected.push_back(std::size_t(found - available.begin()));
  }
  return selected;
}

std::vector<AttributeColumn> detail::makeColumns(const std::vector<AttributeDesc>& available,
                                                 const std::vector<std::size_t>& selected) {
  std::vector<AttributeColumn> columns;
  for (std::size_t index : selected) columns.push_back({available[index].name, available[index].arity, {}});
  return columns;
}

void detail::syncColumns(std::vector<AttributeColumn>& columns, const std::vector<AttributeColumn>& expected) {
  columns.resize(expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    if (columns[i].name != expected[i].name) columns[i].name = expected[i].name;
    columns[i].arity = expected[i].arity;
    columns[i].values.clear();
  }
}

void detail::fillFromFloatStreams(ParticleChunk& chunk, std::size_t n, const FloatStreams& streams,
                                  const std::vector<AttributeDesc>& attributes, const std::vector<std::size_t>& selected,
                                  const std::function<int(std::size_t)>& arity,
                                  const std::function<void(std::size_t, std::size_t, float*)>& read) {
  std::vector<const float*> done(streams.count, nullptr);  // per stream: where its values went
  auto fill = [&](std::size_t stream, float* out) {
    if (done[stream])
      std::memcpy(out, done[stream], n * std::size_t(arity(stream)) * sizeof(float));
    else
      read(stream, n, out);
    done[stream] = out;
  };
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
  chunk.positions.resize(n);
  fill(0, &chunk.positions[0].x);
  chunk.velocities.resize(streams.velocity ? n : 0);
  if (streams.velocity) fill(streams.velocityStream, &chunk.velocities[0].x);
  chunk.attributes.resize(selected.size());
  for (std::size_t i = 0; i < selected.size(); ++i) {
    AttributeColumn& column = chunk.attributes[i];
    column.name = attributes[selected[i]].name;
    column.arity = attributes[selected[i]].arity;
    column.values.resize(n * std::size_t(column.arity));
    fill(streams.columnStreams[i], column.values.data());
  }
}

}  // namespace flipscope
