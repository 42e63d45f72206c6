// Writing a file into a cache that other psc processes (the ranks of a
// distributed job, say) may be filling at the same moment: readers see the
// whole file or none of it.
#pragma once

#include <filesystem>
#include <string_view>

namespace psc {

// Writes `data` under a name no other writer uses, then renames it to `path`;
// false if either step fails (the temporary file is removed).
bool writeCacheFile(const std::filesystem::path& path, std::string_view data);

}  // namespace psc
