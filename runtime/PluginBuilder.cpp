#include "PluginBuilder.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <unistd.h>

#include "ChildProcess.h"
#include "InstallPaths.h"
#include "base/Sha1.h"
#include "plugin_host/DeviceImage.h"

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

bool writeText(const fs::path& p, const std::string& text) {
    std::ofstream out(p, std::ios::binary);
    out << text;
    return static_cast<bool>(out);
}

std::string readFile(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
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

namespace {

using Step = PluginBuild::Step;

// The compiler's failure, in words (its output, or the limit that stopped it).
std::string failureLog(const Step& step, const ChildLimits& limits) {
    std::string log = readFile(step.log);
    if (const std::string limit = limitMessage(step.result, limits, log); !limit.empty()) {
        return fmt::format("the C++ compiler {}\n{}", limit, log);
    }
    if (!step.result.error.empty()) return step.result.error + "\n" + log;
    if (!log.empty()) return log;
    return step.result.signal ? fmt::format("the compiler was killed by signal {}", step.result.signal)
                              : fmt::format("the compiler exited with status {}", step.result.exitCode);
}

std::string commandLine(const std::vector<std::string>& argv) {
    std::string command;
    for (const auto& a : argv) command += (command.empty() ? "" : " ") + shellQuote(a);
    return command;
}

// Units 0..units-1 shared out among `processes` compiles (bit k of a mask:
// unit k), each unit to the least loaded: a rule unit holds about 16 kB of
// rule code; unit 0, the host side and the turn, costs about as much as
// five of them (atlas, the development machine: 5.6 s against about 1 s).
std::vector<uint64_t> shareOut(int units, int processes) {
    constexpr int kUnitZeroCost = 5;
    std::vector<uint64_t> masks(static_cast<size_t>(processes), 0);
    std::vector<int> load(static_cast<size_t>(processes), 0);
    for (int k = 0; k < units; ++k) {
        const size_t least = static_cast<size_t>(std::min_element(load.begin(), load.end()) - load.begin());
        masks[least] |= uint64_t{1} << k;
        load[least] += k == 0 ? kUnitZeroCost : 1;
    }
    return masks;
}

}  // namespace

PluginBuild::PluginBuild(const std::string& source, const BuildOptions& options, const std::string& extraKey)
    : options_(options), start_(std::chrono::steady_clock::now()) {
    compiler_ = options.compiler;
    if (compiler_.empty()) compiler_ = std::getenv("CXX") && *std::getenv("CXX") ? std::getenv("CXX") : "c++";
    flags_ = "-std=c++17 " + options.optimization + " -fPIC -pthread -w -fvisibility=hidden";
    if (options.native) flags_ += " -march=native";
    if (!options.flags.empty()) flags_ += " " + options.flags;
    // As PSC_NVRTC_OPTIONS for NVRTC: to measure a flag, or to build code
    // paths the GPU takes (-DPSC_MOVE_OVER_BOARDS=1) for tests on the CPU.
    if (const char* extra = std::getenv("PSC_CXX_OPTIONS"); extra && *extra) flags_ += std::string(" ") + extra;
    const int units = std::max(1, options.units);
    dir_ = options.cacheDir.empty() ? defaultCacheDir() : options.cacheDir;
    host_ = options.hostLibrary.empty() ? (fs::path(pscLibraryDir()) / kPluginHostFile).string() : options.hostLibrary;
    const std::string hostBytes = readFile(host_);
    if (hostBytes.empty()) {
        fail("psc's plugin host library, which every plugin links, is not installed (" + host_ + ")");
        return;
    }
    key_ = sha1Hex(fmt::format("{}\n{}\n{}\n{}\n{}\n{}", compiler_, flags_, units, extraKey, sha1Hex(hostBytes), source));
    result_.pluginPath = (dir_ / (key_ + ".so")).string();
    std::error_code ec;
    if (fs::exists(result_.pluginPath, ec)) {
        result_.ok = true;
        result_.cached = true;
        done_ = true;
        return;
    }
    fs::create_directories(dir_, ec);
    if (ec) {
        fail("cannot create the plugin cache " + dir_.string() + ": " + ec.message());
        return;
    }
    unique_ = fmt::format("{}.{}", key_, static_cast<long>(getpid()));
    source_ = dir_ / (unique_ + ".cpp");
    if (!writeText(source_, source)) {
        fail("cannot write " + source_.string());
        return;
    }
    limits_ = options.limits ? *options.limits : defaultCompileLimits();
    // One process per core, or $PSC_COMPILE_JOBS: the units shared out by
    // expected cost, all compiled at once, then linked.
    unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    if (const char* jobs = std::getenv("PSC_COMPILE_JOBS"); jobs && std::atoi(jobs) > 0) {
        cores = static_cast<unsigned>(std::atoi(jobs));
    }
    const int processes = static_cast<int>(std::min<unsigned>(cores, static_cast<unsigned>(units)));
    if (processes == 1) {
        // Compiled and linked at once (a CUDA plugin's device code is added to it afterwards: finish).
        std::vector<std::string> arguments = {"-shared", "-o", linkedPath().string(), source_.string()};
        for (const auto& a : hostLinkArguments()) arguments.push_back(a);
        addStep(compileCommand(arguments));
        linkedAtOnce_ = true;
    } else {
        for (const uint64_t mask : shareOut(units, processes)) addObject(source_, {fmt::format("-DPSC_UNIT_MASK={}ull", mask)});
    }
    // Started from this thread, not a helper one: NVRTC's forked copy of psc
    // (runForked) may start next, and a copy made while another thread ran
    // could inherit a lock that thread held (a sanitizer's allocator's).
    for (auto& step : steps_) step.running = startChild(step.argv, step.log, limits_);
    compileSteps_ = steps_.size();
}

fs::path PluginBuild::linkedPath() const { return dir_ / (unique_ + ".so"); }

void PluginBuild::collectCompiles() {
    if (collected_) return;
    collected_ = true;
    for (size_t k = 0; k < compileSteps_; ++k) {
        steps_[k].result = steps_[k].running.wait();
        result_.unitSeconds.push_back(steps_[k].result.seconds);
    }
}

bool PluginBuild::compilesOk() const {
    return std::all_of(steps_.begin(), steps_.begin() + static_cast<std::ptrdiff_t>(compileSteps_),
                       [](const Step& s) { return s.result.ok(); });
}

void PluginBuild::startLink() {
    std::vector<std::string> link = words(compiler_);
    for (const auto& a : {"-shared", "-pthread", "-o"}) link.push_back(a);
    link.push_back(linkedPath().string());
    for (const auto& o : objects_) link.push_back(o.string());
    for (const auto& a : hostLinkArguments()) link.push_back(a);
    addStep(std::move(link));
    steps_.back().running = startChild(steps_.back().argv, steps_.back().log, limits_);
    linkStarted_ = true;
}

void PluginBuild::advance() {
    if (done_ || linkedAtOnce_ || linkStarted_) return;
    for (size_t k = 0; k < compileSteps_; ++k) {
        if (!steps_[k].running.ended()) return;
    }
    collectCompiles();
    if (compilesOk()) startLink();
}

PluginBuild::~PluginBuild() {
    for (auto& step : steps_) step.running = RunningChild();
    cleanUp();
}

// The whole host archive: nothing in the game's code calls the ABI functions
// it exports, so the linker would otherwise leave them out.
std::vector<std::string> PluginBuild::hostLinkArguments() const {
    return {"-Wl,--whole-archive", host_, "-Wl,--no-whole-archive"};
}

void PluginBuild::fail(const std::string& why) {
    result_.log = why;
    done_ = true;
}

std::vector<std::string> PluginBuild::compileCommand(const std::vector<std::string>& arguments) const {
    std::vector<std::string> argv = words(compiler_);
    for (const auto& f : words(flags_)) argv.push_back(f);
    argv.insert(argv.end(), arguments.begin(), arguments.end());
    return argv;
}

void PluginBuild::addStep(std::vector<std::string> argv) {
    result_.command += (result_.command.empty() ? "" : "\n") + commandLine(argv);
    if (options_.verbose) fmt::print(stderr, "psc: {}\n", commandLine(argv));
    steps_.push_back({std::move(argv), (dir_ / fmt::format("{}.{}.log", unique_, steps_.size())).string(), {}, {}});
}

void PluginBuild::addObject(const fs::path& source, std::vector<std::string> arguments) {
    objects_.push_back(dir_ / fmt::format("{}.{}.o", unique_, objects_.size()));
    for (const auto& a : {std::string("-c"), std::string("-o"), objects_.back().string(), source.string()}) arguments.push_back(a);
    addStep(compileCommand(arguments));
}

void PluginBuild::cleanUp() {
    std::error_code ec;
    for (const auto& step : steps_) fs::remove(step.log, ec);
    for (const auto& o : objects_) fs::remove(o, ec);
    if (!deviceImage_.empty()) fs::remove(deviceImage_, ec);
    if (!source_.empty()) {
        if (result_.ok && !result_.cached) fs::rename(source_, dir_ / (key_ + ".cpp"), ec);
        else fs::remove(source_, ec);
    }
    steps_.clear();
    objects_.clear();
    source_.clear();
    deviceImage_.clear();
}

BuildResult PluginBuild::finish(const std::string& deviceImage) {
    if (done_) return result_;
    collectCompiles();
    done_ = true;
    bool ok = compilesOk();
    const fs::path tmp = linkedPath();
    if (ok && !linkedAtOnce_) {
        if (!linkStarted_) startLink();
        Step& link = steps_[compileSteps_];
        link.result = link.running.wait();
        ok = link.result.ok();
        result_.linkSeconds = link.result.seconds;
    }
    if (ok && !deviceImage.empty()) {
        // A section the loader leaves alone, added in place; objcopy ships with
        // the binutils that the C++ compiler links with.
        deviceImage_ = dir_ / (unique_ + ".device");
        if (!writeText(deviceImage_, deviceImage)) {
            result_.log = "cannot write " + deviceImage_.string();
            ok = false;
        } else {
            addStep({"objcopy", "--add-section", std::string(psc_host::kDeviceImageSection) + "=" + deviceImage_.string(), tmp.string()});
            Step& added = steps_.back();
            added.result = runChild(added.argv, added.log, limits_);
            ok = added.result.ok();
            result_.deviceCodeSeconds = added.result.seconds;
        }
    }
    for (const auto& step : steps_) {
        if (!step.result.ok() && result_.log.empty()) result_.log = failureLog(step, limits_);
    }
    std::error_code ec;
    if (ok) {
        fs::rename(tmp, result_.pluginPath, ec);
        result_.ok = !ec;
        if (ec) result_.log = "cannot move the plugin into the cache: " + ec.message();
    } else {
        fs::remove(tmp, ec);
    }
    cleanUp();
    result_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    return result_;
}

BuildResult buildCpuPlugin(const std::string& source, const BuildOptions& options) {
    return PluginBuild(source, options).finish();
}

}  // namespace psc
