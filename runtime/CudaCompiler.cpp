#include "CudaCompiler.h"

#include "ChildProcess.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string_view>
#include <dlfcn.h>
#include <unistd.h>

#include "InstallPaths.h"
#include "NvrtcModule.h"

namespace psc {
namespace {

namespace fs = std::filesystem;

std::string readAll(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

struct LoadedNvrtc {
    const NvrtcModule* module = nullptr;
    std::string problem;  // why module is null
};

// The NVRTC module beside the running executable (NvrtcModule.h), loaded once.
const LoadedNvrtc& nvrtcModule() {
    static const LoadedNvrtc loaded = [] {
        LoadedNvrtc l;
#if PSC_HAVE_NVRTC
        const std::string path = (fs::path(pscLibraryDir()) / kNvrtcModuleFile).string();
        std::error_code ec;
        if (!fs::exists(path, ec)) {
            l.problem = "psc's NVRTC module is not installed (" + path + ")";
            return l;
        }
        void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (!handle) {
            l.problem = fmt::format("NVRTC cannot be loaded (the CUDA Toolkit's libraries are needed): {}", dlerror());
            return l;
        }
        const auto entry = reinterpret_cast<decltype(&psc_nvrtc_module)>(dlsym(handle, kNvrtcModuleEntry));
        const NvrtcModule* m = entry ? entry() : nullptr;
        if (!m || m->version != kNvrtcModuleVersion || m->optionsSize != sizeof(CudaCompileOptions) ||
            m->resultSize != sizeof(CudaCompileResult)) {
            l.problem = path + " is not the NVRTC module of this psc";
            return l;
        }
        l.module = m;
#else
        l.problem = "this psc was built without NVRTC (the CUDA Toolkit was not found)";
#endif
        return l;
    }();
    return loaded;
}

std::string nvccPath() {
    for (const char* candidate : {"/usr/local/cuda/bin/nvcc"}) {
        if (fs::exists(candidate)) return candidate;
    }
    return "nvcc";
}

}  // namespace

std::vector<std::string> compilerOptionsFromEnvironment() {
    std::vector<std::string> options;
    const char* text = std::getenv("PSC_NVRTC_OPTIONS");
    std::istringstream words(text ? text : "");
    for (std::string w; words >> w;) options.push_back(w);
    return options;
}

namespace {

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
    common.insert(common.end(), options.extraOptions.begin(), options.extraOptions.end());
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

namespace {
// The value of `#define NAME value` in a generated source, or fallback.
int definedNumber(const std::string& source, const std::string& name, int fallback) {
    const std::string define = "#define " + name + " ";
    const size_t at = source.find(define);
    return at == std::string::npos ? fallback : std::atoi(source.c_str() + at + define.size());
}
}  // namespace

int compileUnitsOf(const std::string& source) {
    const int units = definedNumber(source, "PSC_COMPILE_UNITS", 1);
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

bool cudaCompilerAvailable(const std::string& compiler) { return cudaCompilerProblem(compiler).empty(); }

std::string cudaCompilerProblem(const std::string& compiler) {
    if (compiler == "nvcc") return findProgram(nvccPath()).empty() ? "nvcc is not installed" : "";
    if (compiler == "nvrtc") return nvrtcModule().problem;
    return "unknown CUDA compiler " + compiler;
}

namespace {

// A compile result as bytes, from NVRTC's forked process to psc.
void putString(std::string& out, std::string_view s) {
    const uint64_t n = s.size();
    out.append(reinterpret_cast<const char*>(&n), sizeof n);
    out.append(s);
}
void putStrings(std::string& out, const std::vector<std::string>& v) {
    putString(out, std::to_string(v.size()));
    for (const auto& s : v) putString(out, s);
}

struct Reader {
    std::string_view in;
    bool ok = true;
    std::string string() {
        uint64_t n = 0;
        if (in.size() < sizeof n) return ok = false, std::string();
        std::memcpy(&n, in.data(), sizeof n);
        in.remove_prefix(sizeof n);
        if (in.size() < n) return ok = false, std::string();
        std::string s(in.substr(0, n));
        in.remove_prefix(n);
        return s;
    }
    std::vector<std::string> strings() {
        const size_t n = std::strtoull(string().c_str(), nullptr, 10);
        std::vector<std::string> v;
        for (size_t i = 0; ok && i < n; ++i) v.push_back(string());
        return v;
    }
};

std::string pack(const CudaCompileResult& r) {
    std::string out;
    putString(out, r.ok ? "1" : "0");
    putString(out, std::string_view(r.cubin.data(), r.cubin.size()));
    putStrings(out, r.ptx);
    putString(out, r.log);
    putStrings(out, r.options);
    putString(out, std::to_string(r.units));
    putStrings(out, r.linkOptions);
    std::vector<std::string> seconds;
    for (double t : r.unitSeconds) seconds.push_back(fmt::format("{}", t));
    putStrings(out, seconds);
    return out;
}

bool unpack(std::string_view bytes, CudaCompileResult& r) {
    Reader in{bytes};
    r.ok = in.string() == "1";
    const std::string cubin = in.string();
    r.cubin.assign(cubin.begin(), cubin.end());
    r.ptx = in.strings();
    r.log = in.string();
    r.options = in.strings();
    r.units = std::atoi(in.string().c_str());
    r.linkOptions = in.strings();
    for (const auto& t : in.strings()) r.unitSeconds.push_back(std::atof(t.c_str()));
    return in.ok && in.in.empty();
}

}  // namespace

CudaCompileResult compileCuda(const std::string& source, const std::string& name, const CudaCompileOptions& options,
                              const std::function<void()>& meanwhile) {
    CudaCompileResult r;
    const auto start = std::chrono::steady_clock::now();
    // The source's cap on registers a thread (codegen/CppSource.cpp), for
    // every unit, or the one program.
    CudaCompileOptions unitOptions = options;
    if (const int cap = definedNumber(source, "PSC_UNIT_MAX_REGISTERS", 0); cap > 0) {
        unitOptions.extraOptions.push_back(fmt::format("-maxrregcount={}", cap));
    }
    if (options.compiler == "nvcc") {
        r.ok = nvccCompile(source, name, unitOptions, r);
    } else if (const NvrtcModule* nvrtc = nvrtcModule().module) {
        // A syntax check reads the source once, as one program: that is all of
        // every unit's code (tests/correctness/cuda_compile_units.py compiles and
        // links units), and CI checks a thousand games so.
        const int units = options.syntaxOnly ? 1 : compileUnitsOf(source);
        // In a forked copy, so that a compile that runs too long stops (NVRTC
        // has no time limit of its own) and dies with psc.
        const double wall = options.wallSeconds >= 0 ? options.wallSeconds : defaultCompileLimits().wallSeconds;
        std::string packed;
        const ChildResult child = runForked(
            [&] {
                CudaCompileResult inChild;
                inChild.ok = nvrtc->compile(source, name, unitOptions, units, inChild);
                return pack(inChild);
            },
            &packed, wall, meanwhile);
        if (child.timedOut) {
            r.timedOut = true;
            r.log = fmt::format("NVRTC {}\n", limitMessage(child, ChildLimits{wall, 0}, ""));
        } else if (!child.ok() || !unpack(packed, r)) {
            r.ok = false;
            r.log = child.error.empty() ? fmt::format("NVRTC's process ended without a result ({})\n",
                                                      child.signal ? fmt::format("signal {}", child.signal)
                                                                   : fmt::format("status {}", child.exitCode))
                                        : child.error + "\n";
        }
    } else {
        r.log = nvrtcModule().problem + "\n";
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
