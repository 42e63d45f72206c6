// Reading a game file, with limits that keep bad input from exhausting memory.
#pragma once

#include <optional>
#include <string>

namespace psc::cli {

// The largest game psc reads (the largest known game is about 256 KB).
inline constexpr size_t kMaxSourceBytes = 8u << 20;

// Reads `path`; on failure prints "path: error: ..." and returns nothing.
std::optional<std::string> readSource(const std::string& path);

}  // namespace psc::cli
