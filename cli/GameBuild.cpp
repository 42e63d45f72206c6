#include "GameBuild.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "CppSource.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include "CacheFile.h"
#include "Diagnose.h"
#include "base/Sha1.h"

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

codegen::DeviceCodeFiles deviceCodeFiles(const CudaCompileResult& r, const fs::path& cubin, const fs::path& ptx) {
    codegen::DeviceCodeFiles files{fs::absolute(cubin).string(), fs::absolute(ptx).string(), {}, r.stackBytes};
    for (const auto& unit : r.ptx) files.ptxBytes.push_back(unit.size());
    return files;
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

}  // namespace

std::string deviceCodeKey(const std::string& cudaSource, const GameBuildOptions& options) {
    return sha1Hex(fmt::format("{}\n{}\n{}\n{}\n{}", options.cuda.compiler, options.cuda.architecture, options.cuda.fastCompile,
                               fmt::join(options.cuda.extraOptions, " "), cudaSource));
}

namespace {

// compileDeviceCode for a cudaSource already made.
std::optional<CudaCompileResult> compileDeviceSource(const std::string& source, const std::string& layout,
                                                     const std::string& text, const std::string& path,
                                                     const GameBuildOptions& options, codegen::DeviceCodeFiles* files) {
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
        if (options.build.verbose) fmt::print(stderr, "psc: CUDA code from the cache ({})\n", cubinPath.string());
        if (files) *files = deviceCodeFiles(r, cubinPath, ptxPath);
        return r;
    }
    if (const std::string problem = cudaCompilerProblem(options.cuda.compiler); !problem.empty()) {
        fmt::print(stderr, "{}: error: the CUDA compiler {} is not available: {}\n", path, options.cuda.compiler, problem);
        return std::nullopt;
    }
    CudaCompileResult r = compileCuda(source, sha1Hex(text).substr(0, 12), options.cuda);
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
        if (r.ok) fmt::print(stderr, "psc: kernels' stack: at most {} bytes a thread (stackBound)\n", r.stackBytes);
    }
    if (!r.ok) {
        fmt::print(stderr, "{}: error: compiling the CUDA code failed\n{}\n", path, r.log);
        return std::nullopt;
    }
    fmt::print(stderr, "psc: CUDA compile ({}, {} layout{}) {:.2f} s\n", options.cuda.compiler, layout,
               r.units > 1 ? fmt::format(", {} units", r.units) : std::string(), r.seconds);
    fs::create_directories(dir, ec);
    const bool stored = writeCacheFile(cubinPath, std::string_view(r.cubin.data(), r.cubin.size())) &&
                        writeCacheFile(ptxPath, joinUnits(r.ptx)) && writeCacheFile(logPath, r.log);
    if (files) {
        if (!stored) {
            fmt::print(stderr, "{}: error: cannot write the CUDA code into the cache {}\n", path, dir.string());
            return std::nullopt;
        }
        *files = deviceCodeFiles(r, cubinPath, ptxPath);
    }
    return r;
}

}  // namespace

std::optional<CudaCompileResult> compileDeviceCode(const ir::Game& game, const std::string& text,
                                                   const std::string& path, const GameBuildOptions& options,
                                                   codegen::DeviceCodeFiles* files) {
    codegen::SourceOptions so = sourceOptions(text, path, options);
    so.decidedRuleForm = codegen::ruleForm(game, so);
    return compileDeviceSource(codegen::cudaSource(game, so), codegen::gpuStateLayout(game, so), text, path, options, files);
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
        // The host side compiles while NVRTC does; the device code joins it at the link.
        const std::string deviceSource = codegen::cudaSource(game, so);
        PluginBuild host(codegen::cudaPluginSource(game, so), build, deviceCodeKey(deviceSource, options));
        codegen::DeviceCodeFiles files;
        if (!host.cached() && !compileDeviceSource(deviceSource, codegen::gpuStateLayout(game, so), text, path, options, &files)) {
            return nullptr;
        }
        built = host.cached() ? host.finish() : host.finish(codegen::deviceCodeSource(files));
    }
    if (!built.ok) {
        fmt::print(stderr, "{}: error: building the plugin failed\n{}\n{}\n", path, built.command, built.log);
        return nullptr;
    }
    if (options.build.verbose) {
        std::string units;
        if (!built.cached && built.unitSeconds.size() > 1) {
            units = fmt::format("; {} compile units in {} processes at once, the device code, then the link:", build.units,
                                built.unitSeconds.size() - 2);
            for (double t : built.unitSeconds) units += fmt::format(" {:.2f}", t);
            units += " s";
        }
        fmt::print(stderr, "psc: plugin {} ({}{})\n", built.pluginPath,
                   built.cached ? "from the cache" : fmt::format("built in {:.2f} s", built.seconds), units);
    }
    std::string error;
    auto plugin = Plugin::open(built.pluginPath, &error);
    if (!plugin) fmt::print(stderr, "{}: error: {}\n", path, error);
    if (pluginPath) *pluginPath = built.pluginPath;
    return plugin;
}

}  // namespace psc::cli
