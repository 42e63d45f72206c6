#include "SourceFile.h"

#include <fmt/format.h>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace psc::cli {

std::optional<std::string> readSource(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        fmt::print(stderr, "{}: error: cannot open the file\n", path);
        return std::nullopt;
    }
    in.seekg(0, std::ios::end);
    std::streamoff size = in.tellg();
    if (size < 0) {
        fmt::print(stderr, "{}: error: cannot read the file\n", path);
        return std::nullopt;
    }
    if (static_cast<size_t>(size) > kMaxSourceBytes) {
        fmt::print(stderr, "{}:1:1: error: the file is {} bytes; psc reads games of at most {} bytes\n", path,
                   static_cast<long long>(size), kMaxSourceBytes);
        return std::nullopt;
    }
    in.seekg(0, std::ios::beg);
    std::string text(static_cast<size_t>(size), '\0');
    in.read(text.data(), size);
    return text;
}

}  // namespace psc::cli
