// What the benches report of repeated timings.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include <nlohmann/json.hpp>

namespace flipscope::tools {

/// The median of `values` (the mean of the middle two for an even count); `values` not empty.
inline double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/// A ratio measured once a run of a repeated comparison: each run's, their median and range,
/// and in how many runs it met its target. On a machine whose times swing from run to run, the
/// spread says more than one run.
struct RunRatios {
  std::vector<double> perRun;
  int met = 0;
  double median() const { return tools::median(perRun); }
  double min() const { return *std::min_element(perRun.begin(), perRun.end()); }
  double max() const { return *std::max_element(perRun.begin(), perRun.end()); }
  void add(double ratio, bool metTarget) {
    perRun.push_back(ratio);
    met += metTarget;
  }
  nlohmann::json json() const {
    return {{"per_run", perRun}, {"median", median()}, {"min", min()}, {"max", max()}, {"met_runs", met}};
  }
};

}  // namespace flipscope::tools
