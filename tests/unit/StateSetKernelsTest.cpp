// Search's GPU duplicate detection: its kernels compile for the GPUs psc
// targets (running them needs a GPU: tests/search/device_search_test.py).
#include <catch2/catch.hpp>

#include <string>

#include "CudaCompiler.h"

namespace psc::search {
const std::string& stateSetKernelSource();
}

TEST_CASE("search's state-set kernels compile with NVRTC", "[cuda][search]") {
    REQUIRE(psc::cudaCompilerAvailable("nvrtc"));
    psc::CudaCompileOptions options;
    options.architecture = 90;
    const psc::CudaCompileResult r = psc::compileCuda(psc::search::stateSetKernelSource(), "psc_state_set", options);
    INFO(r.log);
    REQUIRE(r.ok);
    CHECK_FALSE(r.cubin.empty());
    REQUIRE(r.ptx.size() == 1);
    for (const char* kernel : {"psc_set_insert", "psc_set_count", "psc_set_scan", "psc_set_append", "psc_set_rehash",
                               "psc_set_add_root", "psc_beam_histogram", "psc_beam_count_ties",
                               "psc_beam_count_kept", "psc_beam_pack"}) {
        CHECK(r.ptx[0].find(std::string(".entry ") + kernel) != std::string::npos);
    }
}
