// psc compiles CUDA code with NVRTC through a module it loads at run time
// (libpsc_nvrtc.so, in lib/psc/ beside the binary's bin/ folder), so that psc
// itself needs no CUDA library: it starts, and builds CPU plugins, on
// machines without the CUDA Toolkit, and builds CUDA plugins where the
// toolkit's NVRTC and nvJitLink libraries can be loaded.
#pragma once

#include <string>

#include "CudaCompiler.h"

namespace psc {

// The module is built with psc and must match it: its entry point reports
// this version and the sizes of the structures it fills.
constexpr int kNvrtcModuleVersion = 2;

struct NvrtcModule {
    int version;
    size_t optionsSize;  // sizeof(CudaCompileOptions)
    size_t resultSize;   // sizeof(CudaCompileResult)
    // Compiles `source` as `units` NVRTC programs (relocatable and linked with
    // nvJitLink when more than one); fills r's cubin, ptx, log and options.
    bool (*compile)(const std::string& source, const std::string& name, const CudaCompileOptions& options, int units,
                    CudaCompileResult& r);
};

// The module's file name, in psc's library folder (InstallPaths.h).
constexpr const char* kNvrtcModuleFile = "libpsc_nvrtc.so";
constexpr const char* kNvrtcModuleEntry = "psc_nvrtc_module";

}  // namespace psc

extern "C" const psc::NvrtcModule* psc_nvrtc_module();
