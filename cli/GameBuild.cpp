#include "GameBuild.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "CppSource.h"

#include <filesystem>
#include <functional>
#include <fstream>
#include <sstream>
#include "CacheFile.h"
#include "CubinRegisters.h"
#include "Diagnose.h"
#include "base/Sha1.h"
#include "plugin_host/DeviceImage.h"

namespace psc::cli {

std::optional<ir::Game> compileForBuild(const std::string& text, const std::string& path, const GameBuildOptions& options) {
    CompileResult result = compileSource(text);
    if (!options.quiet) printDiagnostics(stderr, path, result);
    const bool usable = result.status == CompileStatus::Ok || (options.keepGoing && result.status == CompileStatus::Playable);
    if (!usable) {
        fmt::print(stderr, "{}: {}\n", path, verdict(result));
        return std::nullopt;
    }
    return std::move(result.game);
}

codegen::SourceOptions sourceOptions(const std::string& text, const std::string& path, const GameBuildOptions& options) {
    codegen::SourceOptions so;
    so.sourceName = path;
    so.sourceSha1 = sha1Hex(text);
    so.levels = options.levels;
    so.target = options.target == "cpu" ? "cpu" : "cuda";
    so.gpuState = options.gpuState;
    so.cudaUnits = options.cudaUnits;
    so.searchKernels = options.searchKernels;
    so.ruleForm = options.ruleForm;
    return so;
}

namespace {

namespace fs = std::filesystem;

std::string readFile(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// The compile units' PTX texts in one cache file, separated by NUL bytes.
std::string joinUnits(const std::vector<std::string>& ptx) {
    std::string out;
    for (size_t k = 0; k < ptx.size(); ++k) out += (k ? std::string(1, '\0') : std::string()) + ptx[k];
    return out;
}
std::vector<std::string> splitUnits(const std::string& text) {
    std::vector<std::string> units(1);
    for (char c : text) {
        if (c == '\0') units.emplace_back();
        else units.back() += c;
    }
    return units;
}

// ptxas's per-kernel lines (registers, spills, shared memory).
void printResourceReport(const std::string& log) {
    std::istringstream in(log);
    for (std::string line; std::getline(in, line);) {
        if (line.find("ptxas info") != std::string::npos || line.find("spill") != std::string::npos) {
            fmt::print(stderr, "psc: {}\n", line);
        }
    }
}

// The registers a thread of the linked kernels, and of the functions that
// take the most: a kernel takes as many as the most of anything it calls,
// and those set how many of its warps an SM holds.
void printRegisters(const std::vector<char>& cubin) {
    const std::vector<FunctionRegisters> all = cubinRegisters(std::string_view(cubin.data(), cubin.size()));
    if (all.empty()) return;
    std::vector<std::string> kernels, functions;
    for (const FunctionRegisters& f : all) {
        const std::string entry = fmt::format("{} {}", readableFunctionName(f.name), f.registers);
        if (f.kernel) kernels.push_back(entry);
        else if (functions.size() < 4) functions.push_back(entry);
    }
    fmt::print(stderr, "psc: registers a thread, linked: kernels {}; the functions that take the most {}\n",
               fmt::join(kernels, ", "), functions.empty() ? std::string("(none)") : fmt::format("{}", fmt::join(functions, ", ")));
}

// Where a plugin build's time went, for --verbose.
std::string buildTimes(const BuildResult& built) {
    if (built.cached) return "from the cache";
    std::string out = fmt::format("built in {:.2f} s; the host side in {} process{}:", built.seconds, built.unitSeconds.size(),
                                  built.unitSeconds.size() == 1 ? "" : "es");
    for (double t : built.unitSeconds) out += fmt::format(" {:.2f}", t);
    out += built.linkSeconds < 0 ? " s, linked at once" : fmt::format(" s, then the link {:.2f} s", built.linkSeconds);
    if (built.deviceCodeSeconds >= 0) out += fmt::format("; the device code added in {:.2f} s", built.deviceCodeSeconds);
    return out;
}

}  // namespace

std::string deviceCodeKey(const std::string& cudaSource, const GameBuildOptions& options) {
    const std::string fixed = options.cuda.compiler == "nvrtc" ? fmt::format("{}", fmt::join(nvrtcFixedOptions(), " ")) : "";
    return sha1Hex(fmt::format("{}\n{}\n{}\n{}\n{}\n{}", options.cuda.compiler, fixed, options.cuda.architecture,
                               options.cuda.fastCompile, fmt::join(options.cuda.extraOptions, " "), cudaSource));
}

namespace {

// compileDeviceCode for a cudaSource already made.
std::optional<CudaCompileResult> compileDeviceSource(const std::string& source, const std::string& layout,
                                                     const std::string& text, const std::string& path,
                                                     const GameBuildOptions& options,
                                                     const std::function<void()>& meanwhile = {}) {
    const std::string key = deviceCodeKey(source, options);
    const fs::path dir = options.build.cacheDir.empty() ? defaultCacheDir() : options.build.cacheDir;
    const fs::path cubinPath = dir / (key + ".cubin");
    const fs::path ptxPath = dir / (key + ".ptx");
    const fs::path logPath = dir / (key + ".ptxas.log");
    std::error_code ec;
    if (fs::exists(cubinPath, ec) && fs::exists(ptxPath, ec) && fs::exists(logPath, ec)) {
        CudaCompileResult r;
        r.ok = true;
        const std::string cubin = readFile(cubinPath);
        r.cubin.assign(cubin.begin(), cubin.end());
        r.ptx = splitUnits(readFile(ptxPath));
        r.units = static_cast<int>(r.ptx.size());
        r.log = readFile(logPath);
        r.stackBytes = stackBound(r.log, r.ptx);
        if (options.build.verbose) {
            fmt::print(stderr, "psc: CUDA code from the cache ({})\n", cubinPath.string());
            printRegisters(r.cubin);
        }
        return r;
    }
    if (const std::string problem = cudaCompilerProblem(options.cuda.compiler); !problem.empty()) {
        fmt::print(stderr, "{}: error: the CUDA compiler {} is not available: {}\n", path, options.cuda.compiler, problem);
        return std::nullopt;
    }
    CudaCompileResult r = compileCuda(source, sha1Hex(text).substr(0, 12), options.cuda, meanwhile);
    if (options.build.verbose) {
        std::string opts;
        for (const auto& o : r.options) opts += " " + o;
        fmt::print(stderr, "psc: {} options:{}\n", options.cuda.compiler, opts);
        if (r.units > 1) {
            std::string link;
            for (const auto& o : r.linkOptions) link += " " + o;
            std::string times;
            for (double t : r.unitSeconds) times += fmt::format(" {:.2f}", t);
            fmt::print(stderr, "psc: {} compile units at once (-DPSC_UNIT=0..{}), linked by nvJitLink:{}; unit seconds:{}\n",
                       r.units, r.units - 1, link, times);
        }
        printResourceReport(r.log);
        if (r.ok) {
            printRegisters(r.cubin);
            fmt::print(stderr, "psc: kernels' stack: at most {} bytes a thread (stackBound)\n", r.stackBytes);
        }
    }
    if (!r.ok) {
        fmt::print(stderr, "{}: error: compiling the CUDA code failed\n{}\n", path, r.log);
        return std::nullopt;
    }
    fmt::print(stderr, "psc: CUDA compile ({}, {} layout{}) {:.2f} s\n", options.cuda.compiler, layout,
               r.units > 1 ? fmt::format(", {} units", r.units) : std::string(), r.seconds);
    fs::create_directories(dir, ec);
    // A cache that cannot be written costs the next build its NVRTC time, nothing more.
    writeCacheFile(cubinPath, std::string_view(r.cubin.data(), r.cubin.size()));
    writeCacheFile(ptxPath, joinUnits(r.ptx));
    writeCacheFile(logPath, r.log);
    return r;
}

}  // namespace

std::optional<CudaCompileResult> compileDeviceCode(const ir::Game& game, const std::string& text,
                                                   const std::string& path, const GameBuildOptions& options) {
    codegen::SourceOptions so = sourceOptions(text, path, options);
    so.decidedRuleForm = codegen::ruleForm(game, so);
    return compileDeviceSource(codegen::cudaSource(game, so), codegen::gpuStateLayout(game, so), text, path, options);
}

std::unique_ptr<Plugin> loadPlugin(const ir::Game& game, const std::string& text, const std::string& path,
                                   const GameBuildOptions& options, std::string* pluginPath) {
    codegen::SourceOptions so = sourceOptions(text, path, options);
    so.decidedRuleForm = codegen::ruleForm(game, so);
    if (options.build.verbose) fmt::print(stderr, "psc: {}\n", so.decidedRuleForm->reason);
    BuildOptions build = options.build;
    build.units = codegen::hostCompileUnits(game, so);
    BuildResult built;
    if (options.target == "cpu") {
        built = buildCpuPlugin(codegen::cpuPluginSource(game, so), build);
    } else {
        // The host side compiles and links while NVRTC runs; the device code is added to the plugin after.
        const std::string deviceSource = codegen::cudaSource(game, so);
        PluginBuild host(codegen::cudaPluginSource(game, so), build, deviceCodeKey(deviceSource, options));
        if (host.cached()) {
            built = host.finish();
        } else {
            const auto device = compileDeviceSource(deviceSource, codegen::gpuStateLayout(game, so), text, path, options,
                                                    [&] { host.advance(); });
            if (!device) return nullptr;
            psc_host::DeviceImage image;
            image.cubin.assign(device->cubin.begin(), device->cubin.end());
            image.ptx = device->ptx;
            image.stackBytes = device->stackBytes;
            built = host.finish(psc_host::encodeDeviceImage(image));
        }
    }
    if (!built.ok) {
        fmt::print(stderr, "{}: error: building the plugin failed\n{}\n{}\n", path, built.command, built.log);
        return nullptr;
    }
    if (options.build.verbose) fmt::print(stderr, "psc: plugin {} ({})\n", built.pluginPath, buildTimes(built));
    std::string error;
    auto plugin = Plugin::open(built.pluginPath, &error);
    if (!plugin) fmt::print(stderr, "{}: error: {}\n", path, error);
    if (pluginPath) *pluginPath = built.pluginPath;
    return plugin;
}

}  // namespace psc::cli
