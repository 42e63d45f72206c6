#include "CudaCompiler.h"

#include "ChildProcess.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <thread>
#include <unistd.h>

#if PSC_HAVE_NVRTC
#include <nvJitLink.h>
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

// Compiles the source as one program, or as its compile units at once (as
// many at a time as there are cores), relocatable, then linked.
bool nvrtcCompile(const std::string& source, const std::string& name, const CudaCompileOptions& options, CudaCompileResult& r) {
    // NVRTC (12.9+) shares the driver's compute cache, and a hit there returns
    // a cubin without ptxas's report, which sizes the kernels' stack
    // (stackBound).  psc caches whole results itself, so that cache is
    // turned off; NVRTC reads the variable once, at its first compilation.
    setenv("CUDA_CACHE_DISABLE", "1", 1);
    // A syntax check reads the source once, as one program: that is all of
    // every unit's code (tests/correctness/cuda_compile_units.py compiles and
    // links units), and CI checks a thousand games so.
    const int units = options.syntaxOnly ? 1 : compileUnitsOf(source);
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
            outputs[static_cast<size_t>(k)] = nvrtcProgramOutput(source, name, unitOptions, options.syntaxOnly);
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
    std::vector<std::string> common = {"-std=c++17", "-Xptxas=-v", "-DPSC_CUDA=1"};
    if (options.fastCompile != "0") common.push_back("-Ofc=" + options.fastCompile);
    auto command = [&](const std::string& kind, const std::string& arch, const std::string& output) {
        std::vector<std::string> argv = {nvccPath()};
        argv.insert(argv.end(), common.begin(), common.end());
        for (const auto& a : {kind, arch, std::string("-o"), (dir / output).string(), cu.string()}) argv.push_back(a);
        return argv;
    };
    const auto cubinCmd = command("-cubin", fmt::format("-arch=sm_{}", arch), "out.cubin");
    const auto ptxCmd = command("-ptx", fmt::format("-arch=compute_{}", arch), "out.ptx");
    auto joined = [](const std::vector<std::string>& argv) {
        std::string line;
        for (const auto& a : argv) line += (line.empty() ? "" : " ") + a;
        return line;
    };
    r.options = {joined(cubinCmd), joined(ptxCmd)};
    const ChildLimits limits = defaultCompileLimits();
    bool ok = true;
    for (const auto& cmd : {cubinCmd, ptxCmd}) {
        if (!ok) break;
        const std::string logFile = (dir / "log.txt").string();
        const ChildResult child = runChild(cmd, logFile, limits);
        const std::string log = readAll(logFile);
        if (const std::string limit = limitMessage(child, limits, log); !limit.empty()) r.log += "nvcc " + limit + "\n";
        if (!child.error.empty()) r.log += child.error + "\n";
        r.log += log;
        ok = child.ok();
    }
    if (ok) {
        const std::string cubin = readAll(dir / "out.cubin");
        r.cubin.assign(cubin.begin(), cubin.end());
        r.ptx = {readAll(dir / "out.ptx")};
    }
    fs::remove_all(dir, ec);
    return ok && !r.cubin.empty() && !r.ptx[0].empty();
}

}  // namespace

int compileUnitsOf(const std::string& source) {
    const std::string define = "#define PSC_COMPILE_UNITS ";
    const size_t at = source.find(define);
    if (at == std::string::npos) return 1;
    const int units = std::atoi(source.c_str() + at + define.size());
    return units >= 1 && units <= 64 ? units : 1;
}

namespace {

// Each function's stack frame in ptxas's report (the largest, where compile
// units report a function more than once).
std::map<std::string, size_t> stackFrames(const std::string& log) {
    std::map<std::string, size_t> frames;
    std::istringstream in(log);
    std::string function;
    for (std::string line; std::getline(in, line);) {
        const std::string properties = "Function properties for ";
        if (const size_t at = line.find(properties); at != std::string::npos) {
            function = line.substr(at + properties.size());
            while (!function.empty() && std::isspace(static_cast<unsigned char>(function.back()))) function.pop_back();
            continue;
        }
        const size_t at = line.find(" bytes stack frame");
        if (at == std::string::npos || function.empty()) continue;
        size_t begin = at;
        while (begin > 0 && std::isdigit(static_cast<unsigned char>(line[begin - 1]))) --begin;
        if (begin < at) frames[function] = std::max(frames[function], static_cast<size_t>(std::stoull(line.substr(begin, at - begin))));
        function.clear();
    }
    return frames;
}

struct CallGraph {
    std::map<std::string, std::set<std::string>> calls;
    std::set<std::string> kernels;
};

// Who calls whom, from PTX: calls inside each .func/.entry body.
CallGraph callGraph(const std::vector<std::string>& ptx) {
    static const std::regex header(R"(^\s*(?:\.visible\s+|\.weak\s+)?\.(func|entry)\s+(?:\([^)]*\)\s*)?([A-Za-z_$][\w$]*))");
    static const std::regex call(R"(^\s*call(?:\.uni)?\s*(?:\([^)]*\)\s*,)?\s*([A-Za-z_$][\w$]*)?)");
    static const std::regex name(R"(^\s*([A-Za-z_$][\w$]*)\s*,)");
    CallGraph g;
    for (const std::string& unit : ptx) {
        std::istringstream in(unit);
        std::string current;
        bool calleeNext = false;
        std::smatch m;
        for (std::string line; std::getline(in, line);) {
            if (calleeNext) {
                if (std::regex_search(line, m, name)) g.calls[current].insert(m[1]);
                calleeNext = false;
            } else if ((line.find(".func") != std::string::npos || line.find(".entry") != std::string::npos) &&
                       std::regex_search(line, m, header)) {
                current = m[2];
                if (m[1] == "entry") g.kernels.insert(current);
            } else if (!current.empty() && line.find("call") != std::string::npos && std::regex_search(line, m, call)) {
                if (m[1].matched) g.calls[current].insert(m[1]);
                else calleeNext = true;  // the callee is on the next line
            }
        }
    }
    return g;
}

}  // namespace

size_t stackBound(const std::string& log, const std::vector<std::string>& ptx) {
    const std::map<std::string, size_t> frames = stackFrames(log);
    const CallGraph g = callGraph(ptx);
    auto frameOf = [&](const std::string& f) {
        const auto it = frames.find(f);
        return it == frames.end() ? size_t{0} : it->second;
    };
    // Strongly connected components (Tarjan); a component weighs the sum of
    // its frames, kMaxTurnNesting times over when it is a cycle.
    std::map<std::string, int> index, low, component;
    std::vector<std::string> stack;
    std::set<std::string> onStack;
    std::vector<size_t> weight;
    int counter = 0;
    std::function<void(const std::string&)> visit = [&](const std::string& f) {
        index[f] = low[f] = counter++;
        stack.push_back(f);
        onStack.insert(f);
        const auto callees = g.calls.find(f);
        if (callees != g.calls.end()) {
            for (const std::string& c : callees->second) {
                if (!index.count(c)) {
                    visit(c);
                    low[f] = std::min(low[f], low[c]);
                } else if (onStack.count(c)) {
                    low[f] = std::min(low[f], index[c]);
                }
            }
        }
        if (low[f] != index[f]) return;
        weight.push_back(0);
        bool cyclic = false;
        for (std::string member;;) {
            member = stack.back();
            stack.pop_back();
            onStack.erase(member);
            component[member] = static_cast<int>(weight.size() - 1);
            weight.back() += frameOf(member);
            if (member == f) break;
            cyclic = true;
        }
        if (cyclic || (g.calls.count(f) && g.calls.at(f).count(f))) weight.back() *= kMaxTurnNesting;
    };
    // The heaviest chain of components from each kernel.
    std::map<int, std::set<int>> edges;
    for (const std::string& k : g.kernels) {
        if (!index.count(k)) visit(k);
    }
    for (const auto& [caller, callees] : g.calls) {
        if (!component.count(caller)) continue;
        for (const std::string& c : callees) {
            if (component.count(c) && component[c] != component[caller]) edges[component[caller]].insert(component[c]);
        }
    }
    std::map<int, size_t> heaviest;
    std::function<size_t(int)> chain = [&](int c) -> size_t {
        if (const auto it = heaviest.find(c); it != heaviest.end()) return it->second;
        size_t below = 0;
        for (int next : edges[c]) below = std::max(below, chain(next));
        return heaviest[c] = weight[static_cast<size_t>(c)] + below;
    };
    size_t bound = 0;
    for (const std::string& k : g.kernels) bound = std::max(bound, chain(component[k]));
    return bound + kStackMargin;
}

bool cudaCompilerAvailable(const std::string& compiler) {
    if (compiler == "nvcc") return !findProgram(nvccPath()).empty();
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
    r.stackBytes = stackBound(r.log, r.ptx);
    return r;
}

}  // namespace psc
