// CellValueSort: the sort of one cell's quantized attribute values, ascending: the order in which
// a brick stores them in its attribute buffer, cell after cell (Reichl et al. 2014 §3.2). A cell
// holds a few values (about eight where particles lie half a cell apart), so the sort is a
// network in one or two SIMD registers, not a comparison sort's mispredicted branches.
#pragma once

#include <cstdint>

namespace flipscope::detail {

/// Sorts one cell's `count` attribute values in place, ascending: the order in which a brick
/// stores a cell's values, whatever order its particles came in.
void sortCellValues(std::uint16_t* values, std::uint32_t count);

}  // namespace flipscope::detail
