#include "InstallPaths.h"

#include <filesystem>

namespace psc {

std::string pscLibraryDir() {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (ec) return "";
    return (exe.parent_path() / ".." / "lib" / "psc").lexically_normal().string();
}

}  // namespace psc
