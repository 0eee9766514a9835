// What the benches report of repeated timings.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace flipscope::tools {

/// The median of `values` (the mean of the middle two for an even count); `values` not empty.
inline double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace flipscope::tools
