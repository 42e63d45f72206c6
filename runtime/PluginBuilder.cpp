#include "PluginBuilder.h"

#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "ChildProcess.h"
#include "base/Sha1.h"

namespace psc {
namespace {

namespace fs = std::filesystem;

std::string shellQuote(const std::string& s) {
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

// Words separated by spaces: $CXX may be "ccache g++" (run without a shell).
std::vector<std::string> words(const std::string& s) {
    std::vector<std::string> out;
    std::istringstream in(s);
    for (std::string w; in >> w;) out.push_back(w);
    return out;
}

std::string readFile(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

}  // namespace

std::string defaultCacheDir() {
    if (const char* d = std::getenv("PSC_CACHE_DIR"); d && *d) return d;
    if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/psc";
    if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.cache/psc";
    return (fs::temp_directory_path() / "psc-cache").string();
}

BuildResult buildCpuPlugin(const std::string& source, const BuildOptions& options) {
    BuildResult r;
    const auto start = std::chrono::steady_clock::now();
    std::string compiler = options.compiler;
    if (compiler.empty()) compiler = std::getenv("CXX") && *std::getenv("CXX") ? std::getenv("CXX") : "c++";
    std::string flags = "-std=c++17 " + options.optimization + " -fPIC -shared -pthread -w -fvisibility=hidden";
    if (options.native) flags += " -march=native";
    const fs::path dir = options.cacheDir.empty() ? defaultCacheDir() : options.cacheDir;
    const std::string key = sha1Hex(compiler + "\n" + flags + "\n" + source);
    const fs::path plugin = dir / (key + ".so");
    r.pluginPath = plugin.string();
    std::error_code ec;
    if (fs::exists(plugin, ec)) {
        r.ok = true;
        r.cached = true;
        return r;
    }
    fs::create_directories(dir, ec);
    if (ec) {
        r.log = "cannot create the plugin cache " + dir.string() + ": " + ec.message();
        return r;
    }
    const std::string unique = fmt::format("{}.{}", key, static_cast<long>(getpid()));
    const fs::path src = dir / (unique + ".cpp");
    const fs::path tmp = dir / (unique + ".so");
    const fs::path log = dir / (unique + ".log");
    {
        std::ofstream out(src, std::ios::binary);
        out << source;
        if (!out) {
            r.log = "cannot write " + src.string();
            return r;
        }
    }
    std::vector<std::string> argv = words(compiler);
    for (const auto& f : words(flags)) argv.push_back(f);
    for (const auto& a : {std::string("-o"), tmp.string(), src.string()}) argv.push_back(a);
    for (const auto& a : argv) r.command += (r.command.empty() ? "" : " ") + shellQuote(a);
    if (options.verbose) fmt::print(stderr, "psc: {}\n", r.command);
    const ChildLimits limits = options.limits ? *options.limits : defaultCompileLimits();
    const ChildResult child = runChild(argv, log.string(), limits);
    if (!child.ok()) {
        r.log = readFile(log);
        if (const std::string limit = limitMessage(child, limits, r.log); !limit.empty()) {
            r.log = fmt::format("the C++ compiler {}\n{}", limit, r.log);
        } else if (!child.error.empty()) {
            r.log = child.error + "\n" + r.log;
        } else if (r.log.empty()) {
            r.log = child.signal ? fmt::format("the compiler was killed by signal {}", child.signal)
                                 : fmt::format("the compiler exited with status {}", child.exitCode);
        }
        fs::remove(tmp, ec);
    } else {
        fs::rename(tmp, plugin, ec);
        r.ok = !ec;
        if (ec) r.log = "cannot move the plugin into the cache: " + ec.message();
    }
    fs::remove(log, ec);
    if (r.ok) fs::rename(src, dir / (key + ".cpp"), ec);
    else fs::remove(src, ec);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
}

}  // namespace psc
