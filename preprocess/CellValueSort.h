// CellValueSort: the sort of one cell's quantized attribute values, ascending: the order in which
// a brick stores them, cell after cell (store/BrickCodec.cpp; Reichl et al. 2014 §3.2 keep one
// value a cell, we keep every particle's). A cell holds a few values (about eight where particles
// lie half a cell apart), so on x86-64-v2 builds (the default) up to 16 are sorted by a network
// in one or two SSE registers, not a comparison sort's mispredicted branches; elsewhere, and past
// 16, by std::sort.
#pragma once

#include <cstdint>

namespace flipscope::detail {

/// Sorts one cell's `count` attribute values in place, ascending: the order in which a brick
/// stores a cell's values, whatever order its particles came in.
void sortCellValues(std::uint16_t* values, std::uint32_t count);

}  // namespace flipscope::detail
