// The CUDA compiler wrapper: NVRTC's verdicts and the stack bound read from ptxas.
#include <catch2/catch.hpp>

#include "CudaCompiler.h"

using namespace psc;

namespace {

CudaCompileOptions syntaxOnly() {
    CudaCompileOptions o;
    o.syntaxOnly = true;
    return o;
}

}  // namespace

TEST_CASE("NVRTC's syntax check accepts valid CUDA and rejects invalid CUDA", "[cuda]") {
    REQUIRE(cudaCompilerAvailable("nvrtc"));
    const CudaCompileResult good = compileCuda("extern \"C\" __global__ void k(int* p) { p[threadIdx.x] = 1; }", "good", syntaxOnly());
    CHECK(good.ok);
    CHECK(good.cubin.empty());
    const CudaCompileResult bad = compileCuda("extern \"C\" __global__ void k(int* p) { p[threadIdx.x] = undeclared; }", "bad", syntaxOnly());
    CHECK_FALSE(bad.ok);
    CHECK(bad.log.find("undeclared") != std::string::npos);
}

TEST_CASE("NVRTC compiles a kernel to a cubin and PTX in one run", "[cuda]") {
    REQUIRE(cudaCompilerAvailable("nvrtc"));
    const CudaCompileResult r = compileCuda("extern \"C\" __global__ void k(int* p) { p[threadIdx.x] = 1; }", "k", {});
    REQUIRE(r.ok);
    CHECK_FALSE(r.cubin.empty());
    CHECK(r.ptx.find(".entry k") != std::string::npos);
    CHECK(r.options.size() == 5);  // each option once
}

TEST_CASE("the stack bound adds up every function's frame", "[cuda]") {
    const std::string log =
        "ptxas info    : Function properties for rule_a\n"
        "ptxas         .     232 bytes stack frame, 0 bytes spill stores, 0 bytes spill loads\n"
        "ptxas info    : Function properties for psc_run_kernel\n"
        "ptxas         .     1632 bytes stack frame, 160 bytes spill stores, 372 bytes spill loads\n"
        "ptxas info    : Used 255 registers, used 0 barriers, 1632 bytes cumulative stack size\n";
    CHECK(ptxasStackBytes(log) == 232 + 1632 + kStackMargin);
    CHECK(ptxasStackBytes("") == kStackMargin);
}
