#include "CudaCompiler.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#if PSC_HAVE_NVRTC
#include <nvrtc.h>
#endif

namespace psc {
namespace {

namespace fs = std::filesystem;

std::string readAll(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::vector<std::string> commonOptions(const CudaCompileOptions& options) {
    std::vector<std::string> o = {"-std=c++17", "-default-device", "-Xptxas=-v", "-DPSC_CUDA=1"};
    if (options.fastCompile != "0") o.push_back("-Ofc=" + options.fastCompile);
    return o;
}

#if PSC_HAVE_NVRTC
std::string programLog(nvrtcProgram program) {
    size_t size = 0;
    nvrtcGetProgramLogSize(program, &size);
    std::string log(size, '\0');
    if (size) nvrtcGetProgramLog(program, log.data());
    while (!log.empty() && log.back() == '\0') log.pop_back();
    return log;
}

// One NVRTC compilation for a real architecture: NVRTC keeps the PTX it lowered to
// the cubin, so both come from the same run.
bool nvrtcCompile(const std::string& source, const std::string& name, const CudaCompileOptions& options, CudaCompileResult& r) {
    const int arch = options.architecture;
    const bool syntaxOnly = options.syntaxOnly;
    // NVRTC (12.9+) shares the driver's compute cache, and a hit there returns
    // a cubin without ptxas's report, which sizes the kernels' stack
    // (ptxasStackBytes).  psc caches whole results itself, so that cache is
    // turned off; NVRTC reads the variable once, at its first compilation.
    setenv("CUDA_CACHE_DISABLE", "1", 1);
    nvrtcProgram program;
    if (nvrtcCreateProgram(&program, source.c_str(), name.c_str(), 0, nullptr, nullptr) != NVRTC_SUCCESS) {
        r.log += "NVRTC could not create the program\n";
        return false;
    }
    r.options = commonOptions(options);
    r.options.push_back(fmt::format("--gpu-architecture=sm_{}", arch));
    if (syntaxOnly) r.options.push_back("-fdevice-syntax-only");
    std::vector<const char*> argv;
    for (const auto& o : r.options) argv.push_back(o.c_str());
    const nvrtcResult compiled = nvrtcCompileProgram(program, static_cast<int>(argv.size()), argv.data());
    r.log += programLog(program);
    bool ok = compiled == NVRTC_SUCCESS;
    if (!ok) r.log += std::string(nvrtcGetErrorString(compiled)) + "\n";
    if (syntaxOnly) {
        nvrtcDestroyProgram(&program);
        return ok;
    }
    size_t cubinSize = 0, ptxSize = 0;
    ok = ok && nvrtcGetCUBINSize(program, &cubinSize) == NVRTC_SUCCESS && nvrtcGetPTXSize(program, &ptxSize) == NVRTC_SUCCESS;
    if (ok) {
        r.cubin.resize(cubinSize);
        std::string ptx(ptxSize, '\0');
        ok = nvrtcGetCUBIN(program, r.cubin.data()) == NVRTC_SUCCESS && nvrtcGetPTX(program, ptx.data()) == NVRTC_SUCCESS;
        while (!ptx.empty() && ptx.back() == '\0') ptx.pop_back();
        r.ptx = ptx;
    }
    nvrtcDestroyProgram(&program);
    return ok && !r.cubin.empty() && !r.ptx.empty();
}
#endif

std::string nvccPath() {
    for (const char* candidate : {"/usr/local/cuda/bin/nvcc"}) {
        if (fs::exists(candidate)) return candidate;
    }
    return "nvcc";
}

bool nvccCompile(const std::string& source, const std::string& name, const CudaCompileOptions& options, CudaCompileResult& r) {
    const int arch = options.architecture;
    const fs::path dir = fs::temp_directory_path() / fmt::format("psc-nvcc-{}", static_cast<long>(getpid()));
    std::error_code ec;
    fs::create_directories(dir, ec);
    const fs::path cu = dir / (name + ".cu");
    {
        std::ofstream out(cu);
        out << source;
    }
    const std::string common = std::string("-std=c++17 -Xptxas=-v -DPSC_CUDA=1") +
                               (options.fastCompile != "0" ? " -Ofc=" + options.fastCompile : "");
    const std::string cubinCmd = fmt::format("{} {} -cubin -arch=sm_{} -o '{}' '{}'", nvccPath(), common, arch,
                                             (dir / "out.cubin").string(), cu.string());
    const std::string ptxCmd = fmt::format("{} {} -ptx -arch=compute_{} -o '{}' '{}'", nvccPath(), common, arch,
                                           (dir / "out.ptx").string(), cu.string());
    r.options = {cubinCmd, ptxCmd};
    bool ok = true;
    for (const auto& cmd : {cubinCmd, ptxCmd}) {
        const std::string logFile = (dir / "log.txt").string();
        ok = ok && std::system((cmd + " > '" + logFile + "' 2>&1").c_str()) == 0;
        r.log += readAll(logFile);
    }
    if (ok) {
        const std::string cubin = readAll(dir / "out.cubin");
        r.cubin.assign(cubin.begin(), cubin.end());
        r.ptx = readAll(dir / "out.ptx");
    }
    fs::remove_all(dir, ec);
    return ok && !r.cubin.empty() && !r.ptx.empty();
}

}  // namespace

size_t ptxasStackBytes(const std::string& log) {
    size_t total = 0;
    std::istringstream in(log);
    for (std::string line; std::getline(in, line);) {
        const size_t at = line.find(" bytes stack frame");
        if (at == std::string::npos) continue;
        size_t begin = at;
        while (begin > 0 && std::isdigit(static_cast<unsigned char>(line[begin - 1]))) --begin;
        if (begin < at) total += std::stoull(line.substr(begin, at - begin));
    }
    return total + kStackMargin;
}

bool cudaCompilerAvailable(const std::string& compiler) {
    if (compiler == "nvcc") return fs::exists(nvccPath()) || std::system("command -v nvcc > /dev/null 2>&1") == 0;
#if PSC_HAVE_NVRTC
    return compiler == "nvrtc";
#else
    return false;
#endif
}

CudaCompileResult compileCuda(const std::string& source, const std::string& name, const CudaCompileOptions& options) {
    CudaCompileResult r;
    const auto start = std::chrono::steady_clock::now();
    if (options.compiler == "nvcc") {
        r.ok = nvccCompile(source, name, options, r);
    } else {
#if PSC_HAVE_NVRTC
        r.ok = nvrtcCompile(source, name, options, r);
#else
        r.log = "this psc was built without NVRTC (the CUDA Toolkit was not found)";
#endif
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (r.ok && !options.syntaxOnly && r.log.find(" bytes stack frame") == std::string::npos) {
        // Without the report the stack limit would be a guess, and too small a
        // one is an illegal memory access at run time.
        r.ok = false;
        r.log += "the compiler gave no ptxas resource report (needed to size the kernels' stack)\n";
    }
    r.stackBytes = ptxasStackBytes(r.log);
    return r;
}

}  // namespace psc
