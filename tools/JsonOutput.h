// JSON printed by the tools (`info --json`, `bench ... --json`). Paths that are not UTF-8 (Linux
// file names are bytes) are written with U+FFFD in place of the bad bytes rather than failing.
#pragma once

#include <cstdio>

#include <nlohmann/json.hpp>

namespace flipscope::tools {

inline void printJson(const nlohmann::json& j) {
  std::printf("%s\n", j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
}

}  // namespace flipscope::tools
