#include "PluginBuilder.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
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

namespace {

struct Step {
    std::vector<std::string> argv;
    std::string log;
    ChildResult result;
};

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
std::vector<unsigned> shareOut(int units, int processes) {
    constexpr int kUnitZeroCost = 5;
    std::vector<unsigned> masks(static_cast<size_t>(processes), 0);
    std::vector<int> load(static_cast<size_t>(processes), 0);
    for (int k = 0; k < units; ++k) {
        const size_t least = static_cast<size_t>(std::min_element(load.begin(), load.end()) - load.begin());
        masks[least] |= 1u << k;
        load[least] += k == 0 ? kUnitZeroCost : 1;
    }
    return masks;
}

// Runs the steps, at most `parallel` at a time.
void runAll(std::vector<Step>& steps, const ChildLimits& limits, unsigned parallel) {
    std::atomic<size_t> next{0};
    auto worker = [&] {
        for (size_t i; (i = next++) < steps.size();) steps[i].result = runChild(steps[i].argv, steps[i].log, limits);
    };
    std::vector<std::thread> threads;
    for (unsigned t = 1; t < std::min<size_t>(parallel, steps.size()); ++t) threads.emplace_back(worker);
    worker();
    for (auto& t : threads) t.join();
}

}  // namespace

BuildResult buildCpuPlugin(const std::string& source, const BuildOptions& options) {
    BuildResult r;
    const auto start = std::chrono::steady_clock::now();
    std::string compiler = options.compiler;
    if (compiler.empty()) compiler = std::getenv("CXX") && *std::getenv("CXX") ? std::getenv("CXX") : "c++";
    std::string flags = "-std=c++17 " + options.optimization + " -fPIC -pthread -w -fvisibility=hidden";
    if (options.native) flags += " -march=native";
    const int units = std::max(1, options.units);
    const fs::path dir = options.cacheDir.empty() ? defaultCacheDir() : options.cacheDir;
    const std::string key = sha1Hex(fmt::format("{}\n{}\n{}\n{}", compiler, flags, units, source));
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
    {
        std::ofstream out(src, std::ios::binary);
        out << source;
        if (!out) {
            r.log = "cannot write " + src.string();
            return r;
        }
    }
    const ChildLimits limits = options.limits ? *options.limits : defaultCompileLimits();
    auto compilerWith = [&](const std::vector<std::string>& more) {
        std::vector<std::string> argv = words(compiler);
        for (const auto& f : words(flags)) argv.push_back(f);
        for (const auto& a : more) argv.push_back(a);
        return argv;
    };
    // One process: compiled and linked at once.  Several (one per core, or
    // $PSC_COMPILE_JOBS): the units shared out by expected cost, all compiled
    // at once, then linked.
    unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    if (const char* jobs = std::getenv("PSC_COMPILE_JOBS"); jobs && std::atoi(jobs) > 0) {
        cores = static_cast<unsigned>(std::atoi(jobs));
    }
    const int processes = static_cast<int>(std::min<unsigned>(cores, static_cast<unsigned>(units)));
    std::vector<Step> compiles;
    std::vector<fs::path> objects;
    if (processes == 1) {
        compiles.push_back({compilerWith({"-shared", "-o", tmp.string(), src.string()}), (dir / (unique + ".log")).string(), {}});
    } else {
        for (const unsigned mask : shareOut(units, processes)) {
            objects.push_back(dir / fmt::format("{}.{}.o", unique, objects.size()));
            compiles.push_back({compilerWith({fmt::format("-DPSC_UNIT_MASK={}u", mask), "-c", "-o", objects.back().string(), src.string()}),
                                (dir / fmt::format("{}.{}.log", unique, objects.size() - 1)).string(), {}});
        }
    }
    for (const auto& step : compiles) {
        r.command += (r.command.empty() ? "" : "\n") + commandLine(step.argv);
        if (options.verbose) fmt::print(stderr, "psc: {}\n", commandLine(step.argv));
    }
    runAll(compiles, limits, cores);
    std::vector<Step> steps = compiles;
    bool ok = std::all_of(compiles.begin(), compiles.end(), [](const Step& s) { return s.result.ok(); });
    if (ok && processes > 1) {
        std::vector<std::string> link = words(compiler);
        for (const auto& a : {"-shared", "-pthread", "-o"}) link.push_back(a);
        link.push_back(tmp.string());
        for (const auto& o : objects) link.push_back(o.string());
        r.command += "\n" + commandLine(link);
        if (options.verbose) fmt::print(stderr, "psc: {}\n", commandLine(link));
        steps.push_back({link, (dir / (unique + ".link.log")).string(), {}});
        steps.back().result = runChild(steps.back().argv, steps.back().log, limits);
        ok = steps.back().result.ok();
    }
    for (const auto& step : steps) {
        if (!step.result.ok() && r.log.empty()) r.log = failureLog(step, limits);
        if (processes > 1) r.unitSeconds.push_back(step.result.seconds);
    }
    if (ok) {
        fs::rename(tmp, plugin, ec);
        r.ok = !ec;
        if (ec) r.log = "cannot move the plugin into the cache: " + ec.message();
    } else {
        fs::remove(tmp, ec);
    }
    for (const auto& step : steps) fs::remove(step.log, ec);
    for (const auto& o : objects) fs::remove(o, ec);
    if (r.ok) fs::rename(src, dir / (key + ".cpp"), ec);
    else fs::remove(src, ec);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
}

}  // namespace psc
