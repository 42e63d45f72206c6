// Building a plugin from generated source with the system C++ compiler,
// cached by content hash (source, compiler and flags).  A source of several
// compile units (templates/core.h) is compiled as objects at once, one per
// core (the units shared out by their expected cost), then linked.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "ChildProcess.h"

namespace psc {

struct BuildOptions {
    std::string compiler;            // default: $CXX or c++
    std::string optimization = "-O2";
    bool native = false;             // -march=native (faster, not portable)
    std::string cacheDir;            // default: $PSC_CACHE_DIR, else $XDG_CACHE_HOME/psc, else ~/.cache/psc
    bool verbose = false;            // print the compile command
    int units = 1;                   // the source's compile units (codegen::hostCompileUnits)
    std::optional<ChildLimits> limits;  // the compiler's time and memory; default: defaultCompileLimits()
};

struct BuildResult {
    bool ok = false;
    bool cached = false;
    std::string pluginPath;  // in the cache
    std::string command;
    std::string log;         // the compiler's output on failure
    double seconds = 0;
    std::vector<double> unitSeconds;  // each compile process's seconds, then the link's (several processes)
};

BuildResult buildCpuPlugin(const std::string& source, const BuildOptions& options);
std::string defaultCacheDir();

}  // namespace psc
