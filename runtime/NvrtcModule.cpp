// The NVRTC module (NvrtcModule.h): compiles CUDA source in process with
// NVRTC, each compile unit on its own thread, and links the units with
// nvJitLink.  The only part of psc that links the CUDA libraries; psc loads
// it with dlopen.
#include "NvrtcModule.h"

#include <fmt/format.h>
#include <nvJitLink.h>
#include <nvrtc.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <thread>
#include <vector>

namespace psc {
namespace {

std::vector<std::string> commonOptions(const CudaCompileOptions& options) {
    std::vector<std::string> o = nvrtcFixedOptions();
    if (options.fastCompile != "0") o.push_back("-Ofc=" + options.fastCompile);
    o.insert(o.end(), options.extraOptions.begin(), options.extraOptions.end());
    return o;
}

std::string programLog(nvrtcProgram program) {
    size_t size = 0;
    nvrtcGetProgramLogSize(program, &size);
    std::string log(size, '\0');
    if (size) nvrtcGetProgramLog(program, log.data());
    while (!log.empty() && log.back() == '\0') log.pop_back();
    return log;
}

struct UnitOutput {
    bool ok = false;
    std::vector<char> cubin;
    std::string ptx;
    std::string log;
    double seconds = 0;
};

// One NVRTC program for a real architecture: NVRTC keeps the PTX it lowered
// to the cubin, so both come from the same run.
UnitOutput nvrtcProgramOutput(const std::string& source, const std::string& name, const std::vector<std::string>& options,
                              bool syntaxOnly) {
    UnitOutput u;
    const auto start = std::chrono::steady_clock::now();
    nvrtcProgram program;
    if (nvrtcCreateProgram(&program, source.c_str(), name.c_str(), 0, nullptr, nullptr) != NVRTC_SUCCESS) {
        u.log = "NVRTC could not create the program\n";
        return u;
    }
    std::vector<const char*> argv;
    for (const auto& o : options) argv.push_back(o.c_str());
    const nvrtcResult compiled = nvrtcCompileProgram(program, static_cast<int>(argv.size()), argv.data());
    u.log = programLog(program);
    u.ok = compiled == NVRTC_SUCCESS;
    if (!u.ok) u.log += std::string(nvrtcGetErrorString(compiled)) + "\n";
    if (u.ok && !syntaxOnly) {
        size_t cubinSize = 0, ptxSize = 0;
        u.ok = nvrtcGetCUBINSize(program, &cubinSize) == NVRTC_SUCCESS && nvrtcGetPTXSize(program, &ptxSize) == NVRTC_SUCCESS;
        if (u.ok) {
            u.cubin.resize(cubinSize);
            u.ptx.assign(ptxSize, '\0');
            u.ok = nvrtcGetCUBIN(program, u.cubin.data()) == NVRTC_SUCCESS && nvrtcGetPTX(program, u.ptx.data()) == NVRTC_SUCCESS;
            while (!u.ptx.empty() && u.ptx.back() == '\0') u.ptx.pop_back();
        }
        u.ok = u.ok && !u.cubin.empty() && !u.ptx.empty();
    }
    nvrtcDestroyProgram(&program);
    u.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return u;
}

// The units' relocatable cubins linked into one.
bool linkUnits(const std::vector<UnitOutput>& units, int arch, CudaCompileResult& r) {
    const std::string archOption = fmt::format("-arch=sm_{}", arch);
    r.linkOptions = {archOption};
    const char* options[] = {archOption.c_str()};
    nvJitLinkHandle link;
    if (nvJitLinkCreate(&link, 1, options) != NVJITLINK_SUCCESS) {
        r.log += "nvJitLink could not start\n";
        return false;
    }
    bool ok = true;
    for (size_t k = 0; k < units.size() && ok; ++k) {
        const std::string name = fmt::format("unit{}.cubin", k);
        ok = nvJitLinkAddData(link, NVJITLINK_INPUT_CUBIN, units[k].cubin.data(), units[k].cubin.size(), name.c_str()) ==
             NVJITLINK_SUCCESS;
    }
    ok = ok && nvJitLinkComplete(link) == NVJITLINK_SUCCESS;
    size_t size = 0;
    if (ok && nvJitLinkGetLinkedCubinSize(link, &size) == NVJITLINK_SUCCESS && size > 0) {
        r.cubin.resize(size);
        ok = nvJitLinkGetLinkedCubin(link, r.cubin.data()) == NVJITLINK_SUCCESS;
    } else {
        ok = false;
    }
    if (!ok) {
        size_t logSize = 0;
        nvJitLinkGetErrorLogSize(link, &logSize);
        std::string error(logSize, '\0');
        if (logSize) nvJitLinkGetErrorLog(link, error.data());
        while (!error.empty() && error.back() == '\0') error.pop_back();
        r.log += "linking the compile units failed: " + error + "\n";
    }
    nvJitLinkDestroy(&link);
    return ok;
}

// Compiles the source as one program, or as `units` compile units at once
// (as many at a time as there are cores), relocatable, then linked.
bool nvrtcCompile(const std::string& source, const std::string& name, const CudaCompileOptions& options, int units,
                  CudaCompileResult& r) {
    // NVRTC (12.9+) shares the driver's compute cache, and a hit there returns
    // a cubin without ptxas's report, which sizes the kernels' stack
    // (stackBound).  psc caches whole results itself, so that cache is
    // turned off; NVRTC reads the variable once, at its first compilation.
    setenv("CUDA_CACHE_DISABLE", "1", 1);
    r.units = units;
    r.options = commonOptions(options);
    r.options.push_back(fmt::format("--gpu-architecture=sm_{}", options.architecture));
    if (options.syntaxOnly) r.options.push_back("-fdevice-syntax-only");
    if (units > 1) r.options.push_back("-rdc=true");
    std::vector<UnitOutput> outputs(static_cast<size_t>(units));
    std::atomic<int> next{0};
    auto work = [&] {
        for (int k; (k = next++) < units;) {
            std::vector<std::string> unitOptions = r.options;
            if (units > 1) unitOptions.push_back(fmt::format("-DPSC_UNIT={}", k));
            const std::string unitName = units > 1 ? fmt::format("{}_unit{}", name, k) : name;
            outputs[static_cast<size_t>(k)] = nvrtcProgramOutput(source, unitName, unitOptions, options.syntaxOnly);
        }
    };
    const int workers = std::max(1, std::min<int>(units, static_cast<int>(std::thread::hardware_concurrency())));
    std::vector<std::thread> threads;
    for (int w = 1; w < workers; ++w) threads.emplace_back(work);
    work();
    for (auto& t : threads) t.join();
    bool ok = true;
    for (int k = 0; k < units; ++k) {
        const UnitOutput& u = outputs[static_cast<size_t>(k)];
        if (units > 1 && !u.log.empty()) r.log += fmt::format("compile unit {}:\n", k);
        r.log += u.log;
        ok = ok && u.ok;
        r.ptx.push_back(u.ptx);
        r.unitSeconds.push_back(u.seconds);
    }
    if (!ok || options.syntaxOnly) return ok;
    if (units == 1) {
        r.cubin = outputs[0].cubin;
        return true;
    }
    return linkUnits(outputs, options.architecture, r);
}

}  // namespace
}  // namespace psc

extern "C" __attribute__((visibility("default"))) const psc::NvrtcModule* psc_nvrtc_module() {
    static const psc::NvrtcModule module = {psc::kNvrtcModuleVersion, sizeof(psc::CudaCompileOptions),
                                            sizeof(psc::CudaCompileResult), &psc::nvrtcCompile};
    return &module;
}
