// Building a plugin from generated source with the system C++ compiler,
// linked with the plugin host (runtime/plugin_host, built once with psc),
// cached by content hash (source, host, compiler and flags).  A source of several
// compile units (templates/core.h) is compiled as objects at once, one per
// core (the units shared out by their expected cost), then linked.
#pragma once

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "ChildProcess.h"

namespace psc {

struct BuildOptions {
    std::string compiler;            // default: $CXX or c++
    std::string optimization = "-O2";
    std::string flags;               // more compiler flags (the ABI fuzz target's sanitizers)
    bool native = false;             // -march=native (faster, not portable)
    std::string cacheDir;            // default: $PSC_CACHE_DIR, else $XDG_CACHE_HOME/psc, else ~/.cache/psc
    bool verbose = false;            // print the compile command
    int units = 1;                   // the source's compile units (codegen::hostCompileUnits)
    std::optional<ChildLimits> limits;  // the compiler's time and memory; default: defaultCompileLimits()
    std::string hostLibrary;         // default: lib/psc/libpsc_plugin_host.a (InstallPaths.h)
};

struct BuildResult {
    bool ok = false;
    bool cached = false;
    std::string pluginPath;  // in the cache
    std::string command;
    std::string log;         // the compiler's output on failure
    double seconds = 0;
    std::vector<double> unitSeconds;  // each compile process's seconds (with the link, when one process made the plugin)
    double linkSeconds = -1;          // the link of several processes' objects; -1: none
    double deviceCodeSeconds = -1;    // adding the device code to the linked plugin; -1: none
};

// A plugin build under way: the constructor starts compiling `source` (unless
// the cache holds the plugin) and, where one process compiles it, linking it,
// and returns; advance() links the objects of several processes as soon as
// they are compiled; finish() waits, links them if advance() did not, adds
// `deviceImage` (a CUDA plugin's device code, which NVRTC makes meanwhile:
// plugin_host/DeviceImage.h) to the plugin as a section, and caches the
// plugin.  `extraKey` names what deviceImage will hold, for the cache key.
class PluginBuild {
public:
    PluginBuild(const std::string& source, const BuildOptions& options, const std::string& extraKey = "");
    ~PluginBuild();
    PluginBuild(const PluginBuild&) = delete;
    PluginBuild& operator=(const PluginBuild&) = delete;

    bool cached() const { return result_.cached; }
    // Starts the link of several processes' objects once they are all
    // compiled, without waiting for them: called while NVRTC works.
    void advance();
    BuildResult finish(const std::string& deviceImage = "");

    struct Step {
        std::vector<std::string> argv;
        std::string log;
        RunningChild running;
        ChildResult result;
    };

private:
    void fail(const std::string& why);
    std::vector<std::string> compileCommand(const std::vector<std::string>& arguments) const;
    void addStep(std::vector<std::string> argv);
    void addObject(const std::filesystem::path& source, std::vector<std::string> arguments);
    void cleanUp();
    void collectCompiles();
    bool compilesOk() const;
    void startLink();
    // Where the plugin is linked, before it moves into the cache.
    std::filesystem::path linkedPath() const;
    std::vector<std::string> hostLinkArguments() const;

    BuildOptions options_;
    std::chrono::steady_clock::time_point start_;
    std::string compiler_;
    std::string flags_;
    std::filesystem::path dir_;
    std::string host_;  // the plugin host archive
    std::string key_;
    std::string unique_;
    std::filesystem::path source_;
    std::filesystem::path deviceImage_;
    ChildLimits limits_;
    std::vector<Step> steps_;
    std::vector<std::filesystem::path> objects_;
    bool linkedAtOnce_ = false;  // one process: it makes the plugin itself
    size_t compileSteps_ = 0;    // steps_[0, compileSteps_) compile; the link, where started, follows
    bool collected_ = false;     // the compile steps' results are in
    bool linkStarted_ = false;
    bool done_ = false;
    BuildResult result_;
};

BuildResult buildCpuPlugin(const std::string& source, const BuildOptions& options);
std::string defaultCacheDir();

}  // namespace psc
