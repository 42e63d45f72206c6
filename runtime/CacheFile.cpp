#include "CacheFile.h"

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <string>

namespace psc {

bool writeCacheFile(const std::filesystem::path& path, std::string_view data) {
    static std::atomic<unsigned long> written{0};
    const std::filesystem::path tmp =
        path.string() + ".tmp." + std::to_string(static_cast<long>(getpid())) + "." + std::to_string(written++);
    std::error_code ec;
    {
        std::ofstream out(tmp, std::ios::binary);
        out.write(data.data(), static_cast<std::streamsize>(data.size()));
        if (!out.flush()) {
            std::filesystem::remove(tmp, ec);
            return false;
        }
    }
    std::filesystem::rename(tmp, path, ec);
    if (ec) std::filesystem::remove(tmp, ec);
    return !ec;
}

}  // namespace psc
