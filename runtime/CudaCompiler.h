// Compiling a game's device code for CUDA: in process with NVRTC (the
// default, through the module of NvrtcModule.h), or with nvcc.  Produces a
// cubin for the target architecture and PTX for the driver to compile on
// other GPUs.  NVRTC compiles a source that
// declares several compile units (PSC_COMPILE_UNITS, templates/core.h) as
// that many relocatable programs at once, and links them with nvJitLink;
// nvcc compiles it as one program.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace psc {

// $PSC_NVRTC_OPTIONS split at spaces (empty when unset).
std::vector<std::string> compilerOptionsFromEnvironment();

// NVRTC's options in every build, before the caller's and the architecture's
// (runtime/NvrtcModule.cpp), and part of the device code's cache key, so
// that a psc that changes them does not take another's cubins from the cache.
// -minimal: the generated code declares what it uses, so NVRTC's front end
// skips the CUDA runtime's declarations (the same PTX, a few per cent of
// NVRTC's time; docs/performance.md, "The whole build, cold").
inline std::vector<std::string> nvrtcFixedOptions() {
    return {"-std=c++17", "-default-device", "-minimal", "-Xptxas=-v", "-DPSC_CUDA=1"};
}

struct CudaCompileOptions {
    std::string compiler = "nvrtc";  // nvrtc | nvcc
    int architecture = 90;           // sm_90 (H100); PTX for compute_<architecture>
    bool verbose = false;            // print the options and the resource report
    bool syntaxOnly = false;         // NVRTC's front end only: checks the source, makes no code
    // The compilers' -Ofast-compile level: 0 (full optimisation), min, mid or
    // max (fastest compile); docs/performance.md measures what each costs.
    std::string fastCompile = "0";
    // NVRTC runs in a forked copy of psc stopped at this many seconds (0:
    // none); default: PSC_COMPILE_TIMEOUT, as the system compiler's bound.
    double wallSeconds = -1;
    // Appended to the compiler's options, and part of the cache key:
    // $PSC_NVRTC_OPTIONS, split at spaces, for measuring a compiler flag
    // (`-maxrregcount=64`) without rebuilding psc; --verbose prints them.
    std::vector<std::string> extraOptions = compilerOptionsFromEnvironment();
};

struct CudaCompileResult {
    bool ok = false;
    std::vector<char> cubin;               // linked, ready to load
    std::vector<std::string> ptx;          // one per compile unit (the driver links several)
    std::string log;                       // compiler messages, with ptxas's resource report
    std::vector<std::string> options;      // the exact options used (each unit adds -DPSC_UNIT=k)
    int units = 1;                         // programs compiled
    std::vector<std::string> linkOptions;  // nvJitLink's, when units > 1
    double seconds = 0;                // total compile time
    std::vector<double> unitSeconds;   // each unit's NVRTC time (they overlap)
    bool timedOut = false;             // NVRTC stopped at options.wallSeconds (log says so)
    // Stack a thread needs (stackBound): the driver's default limit (1 KB)
    // overflows in games whose state lives in local memory.
    size_t stackBytes = 0;
};

// A bound on the stack any kernel needs: the heaviest chain of calls from a
// kernel, by the stack frames of ptxas's report (`log`) and the calls in the
// PTX (one text per compile unit), plus kStackMargin.  ptxas's own
// "cumulative stack size" leaves out the callees when the call graph has a
// cycle, and psc's has some: a turn that restarts the level, or wins and
// loads the next one, runs the level's start turn inside it.  Turns nest at
// most kMaxTurnNesting deep (an input's turn wins, the next level's start turn
// restarts, the restarted start turn runs; a restart while restarting is
// ignored and a start turn never wins), so a cycle's functions count that
// many times.  The driver reserves the bound for every thread the GPU can
// hold, so a loose one (such as every frame added up) runs out of memory on
// games with large boards.
constexpr int kMaxTurnNesting = 3;  // templates/core.h's, which a unit test checks it equals
constexpr size_t kStackMargin = 1024;
size_t stackBound(const std::string& log, const std::vector<std::string>& ptx);

// The source's PSC_COMPILE_UNITS, or 1.
int compileUnitsOf(const std::string& source);

bool cudaCompilerAvailable(const std::string& compiler);
// Why cudaCompilerAvailable(compiler) is false, in words ("" when it is true).
std::string cudaCompilerProblem(const std::string& compiler);
// `meanwhile`, where given, runs every few milliseconds while NVRTC works (a
// plugin build's host side goes on meanwhile: PluginBuild::advance).
CudaCompileResult compileCuda(const std::string& source, const std::string& name, const CudaCompileOptions& options,
                              const std::function<void()>& meanwhile = {});

}  // namespace psc
