#include "PluginFile.h"

#include <dlfcn.h>
#include <elf.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>

// POSIX calls, not iostreams: a plugin that used those would link much of
// libstdc++'s locale code into itself on some toolchains (Ubuntu's g++ 13
// against a host built with Debian's g++ 12: four times the code, twice the
// link time).

namespace psc_host {
namespace {

// A file opened for reading, closed when it goes.
class ReadOnlyFile {
public:
    explicit ReadOnlyFile(const std::string& path) : fd_(open(path.c_str(), O_RDONLY | O_CLOEXEC)) {}
    ~ReadOnlyFile() {
        if (fd_ >= 0) close(fd_);
    }
    ReadOnlyFile(const ReadOnlyFile&) = delete;
    ReadOnlyFile& operator=(const ReadOnlyFile&) = delete;

    bool isOpen() const { return fd_ >= 0; }
    uint64_t size() const {
        struct stat st {};
        return fstat(fd_, &st) == 0 && st.st_size > 0 ? static_cast<uint64_t>(st.st_size) : 0;
    }
    // `bytes` bytes at `offset`, all of them, or false.
    bool readAt(uint64_t offset, void* out, uint64_t bytes) const {
        auto* p = static_cast<char*>(out);
        while (bytes > 0) {
            const ssize_t n = pread(fd_, p, bytes, static_cast<off_t>(offset));
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) return false;
            p += n;
            offset += static_cast<uint64_t>(n);
            bytes -= static_cast<uint64_t>(n);
        }
        return true;
    }

private:
    int fd_;
};

}  // namespace

std::string pluginFilePath() {
    const auto here = reinterpret_cast<uintptr_t>(&pluginFilePath);
    std::string found;
    if (FILE* maps = std::fopen("/proc/self/maps", "re")) {
        char* line = nullptr;
        size_t capacity = 0;
        while (found.empty() && getline(&line, &capacity, maps) > 0) {
            unsigned long long start = 0, end = 0;
            int pathAt = 0;
            if (std::sscanf(line, "%llx-%llx %*s %*s %*s %*s %n", &start, &end, &pathAt) < 2 || pathAt == 0) continue;
            if (here < start || here >= end || line[pathAt] != '/') continue;
            found = line + pathAt;
            if (!found.empty() && found.back() == '\n') found.pop_back();
        }
        std::free(line);
        std::fclose(maps);
    }
    if (!found.empty()) return found;
    Dl_info info{};
    if (dladdr(reinterpret_cast<void*>(&pluginFilePath), &info) && info.dli_fname) return info.dli_fname;
    return "";
}

bool readElfSection(const std::string& path, const char* name, std::string* bytes, std::string* error) {
    auto failed = [&](const std::string& why) {
        *error = "cannot read " + std::string(name) + " from the plugin file " + (path.empty() ? "(not found)" : path) + ": " + why;
        return false;
    };
    const ReadOnlyFile file(path);
    if (!file.isOpen()) return failed(std::strerror(errno));
    const uint64_t size = file.size();
    Elf64_Ehdr header;
    if (size < sizeof header || !file.readAt(0, &header, sizeof header)) return failed("not an ELF file");
    if (std::memcmp(header.e_ident, ELFMAG, SELFMAG) != 0 || header.e_ident[EI_CLASS] != ELFCLASS64) {
        return failed("not a 64-bit ELF file");
    }
    const uint64_t count = header.e_shnum;
    if (header.e_shentsize != sizeof(Elf64_Shdr) || header.e_shoff > size ||
        count > (size - header.e_shoff) / sizeof(Elf64_Shdr) || header.e_shstrndx >= count) {
        return failed("its section headers are damaged");
    }
    auto section = [&](uint64_t k, Elf64_Shdr* s) { return file.readAt(header.e_shoff + k * sizeof *s, s, sizeof *s); };
    auto inFile = [&](const Elf64_Shdr& s) { return s.sh_offset <= size && s.sh_size <= size - s.sh_offset; };
    Elf64_Shdr names;
    if (!section(header.e_shstrndx, &names) || !inFile(names)) return failed("its section names are damaged");
    std::string table(names.sh_size, '\0');
    if (!file.readAt(names.sh_offset, table.data(), table.size())) return failed("its section names cannot be read");
    const std::string_view wanted(name, std::strlen(name) + 1);  // with its NUL
    for (uint64_t k = 0; k < count; ++k) {
        Elf64_Shdr s;
        if (!section(k, &s)) return failed("its section headers cannot be read");
        if (s.sh_name >= table.size() || std::string_view(table).substr(s.sh_name, wanted.size()) != wanted) continue;
        if (s.sh_type == SHT_NOBITS || !inFile(s)) return failed("the section lies outside the file");
        bytes->assign(s.sh_size, '\0');
        if (!file.readAt(s.sh_offset, bytes->data(), s.sh_size)) return failed("the section cannot be read");
        return true;
    }
    return failed("no such section (the plugin was not built for CUDA by this psc)");
}

}  // namespace psc_host
