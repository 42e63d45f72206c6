// The CUDA compiler wrapper: NVRTC's verdicts and the stack bound read from ptxas.
#include <catch2/catch.hpp>

#include <algorithm>
#include <string_view>

#include "CubinRegisters.h"
#include "CudaCompiler.h"
#include "Templates.h"

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
    REQUIRE(r.ptx.size() == 1);
    CHECK(r.ptx[0].find(".entry k") != std::string::npos);
    // The fixed options and the architecture, each once (extraOptions are
    // $PSC_NVRTC_OPTIONS's, empty in the tests).
    const std::vector<std::string> fixed = nvrtcFixedOptions();
    REQUIRE(r.options.size() == fixed.size() + 1);
    CHECK(std::equal(fixed.begin(), fixed.end(), r.options.begin()));
    CHECK(r.options.back() == "--gpu-architecture=sm_90");
    CHECK(r.units == 1);
}

namespace {

// Two compile units: unit 1 defines what unit 0's kernel calls; a helper
// both use is inline, so each unit has a copy and the copies link as one.
const char* kTwoUnits =
    "#define PSC_COMPILE_UNITS 2\n"
    "__device__ inline __noinline__ int twice(int x) { return 2 * x; }\n"
    "__device__ int shared(int x);\n"
    "#if PSC_UNIT == 1\n"
    "__device__ __noinline__ int shared(int x) { return twice(x) + 1; }\n"
    "#endif\n"
    "#if PSC_UNIT == 0\n"
    "extern \"C\" __global__ void k(int* p) { p[threadIdx.x] = shared(twice(p[threadIdx.x])); }\n"
    "#endif\n";

}  // namespace

TEST_CASE("NVRTC compiles a source's compile units separately and links them into one cubin", "[cuda]") {
    REQUIRE(cudaCompilerAvailable("nvrtc"));
    CHECK(compileUnitsOf(kTwoUnits) == 2);
    CHECK(compileUnitsOf("__global__ void k() {}") == 1);
    const CudaCompileResult r = compileCuda(kTwoUnits, "units", {});
    INFO(r.log);
    REQUIRE(r.ok);
    CHECK(r.units == 2);
    CHECK_FALSE(r.cubin.empty());
    REQUIRE(r.ptx.size() == 2);
    CHECK(r.ptx[0].find(".entry k") != std::string::npos);
    CHECK(r.ptx[1].find(".entry k") == std::string::npos);
    CHECK(r.ptx[1].find("shared") != std::string::npos);
    CHECK(r.linkOptions == std::vector<std::string>{"-arch=sm_90"});

    // A function no unit defines fails the link.
    std::string missing = kTwoUnits;
    missing.replace(missing.find("PSC_UNIT == 1"), 13, "PSC_UNIT == 7");
    const CudaCompileResult unresolved = compileCuda(missing, "missing", {});
    CHECK_FALSE(unresolved.ok);
    CHECK(unresolved.log.find("linking the compile units failed") != std::string::npos);
}

namespace {

// A kernel in unit 0 that calls a function of many live values and one of
// few, both in unit 1.
const char* kHeavyAndLight =
    "#define PSC_COMPILE_UNITS 2\n"
    "namespace psc_game {\n"
    "__device__ unsigned heavy(const unsigned* p);\n"
    "__device__ unsigned light(unsigned x);\n"
    "}\n"
    "#if PSC_UNIT == 1\n"
    "namespace psc_game {\n"
    "__device__ __noinline__ unsigned heavy(const unsigned* p) {\n"
    "    unsigned v[64];\n"
    "#pragma unroll\n"
    "    for (int i = 0; i < 64; ++i) v[i] = p[i * 37];\n"
    "    unsigned s = 0;\n"
    "#pragma unroll\n"
    "    for (int i = 0; i < 64; ++i) s = s * 31u + (v[i] ^ v[63 - i]) * v[(i * 7) % 64];\n"
    "    return s;\n"
    "}\n"
    "__device__ __noinline__ unsigned light(unsigned x) { return x + 1; }\n"
    "}\n"
    "#endif\n"
    "#if PSC_UNIT == 0\n"
    "extern \"C\" __global__ void k(unsigned* p) {\n"
    "    p[threadIdx.x] = psc_game::light(p[threadIdx.x]) + psc_game::heavy(p + threadIdx.x);\n"
    "}\n"
    "#endif\n";

}  // namespace

TEST_CASE("the linked cubin's register counts show the function that sets a kernel's", "[cuda]") {
    REQUIRE(cudaCompilerAvailable("nvrtc"));
    const CudaCompileResult r = compileCuda(kHeavyAndLight, "registers", {});
    INFO(r.log);
    REQUIRE(r.ok);
    const std::vector<FunctionRegisters> all = cubinRegisters(std::string_view(r.cubin.data(), r.cubin.size()));
    auto named = [&](const std::string& name) {
        const auto it = std::find_if(all.begin(), all.end(), [&](const FunctionRegisters& f) {
            return readableFunctionName(f.name) == name;
        });
        REQUIRE(it != all.end());
        return *it;
    };
    const FunctionRegisters k = named("k");
    const FunctionRegisters heavy = named("heavy");
    const FunctionRegisters light = named("light");
    CHECK(k.kernel);
    CHECK_FALSE(heavy.kernel);
    CHECK_FALSE(light.kernel);
    CHECK(heavy.registers > light.registers);
    // Linked from units, the kernel takes the most that anything it calls takes.
    CHECK(k.registers == heavy.registers);
    for (size_t i = 1; i < all.size(); ++i) CHECK(all[i - 1].registers >= all[i].registers);

    // Not a cubin, or a cut one: nothing, and nothing read past its end.
    CHECK(cubinRegisters("").empty());
    CHECK(cubinRegisters("\x7f" "ELF not really an ELF file, but long enough to have a header of sixty-four").empty());
    const std::string_view whole(r.cubin.data(), r.cubin.size());
    CHECK(cubinRegisters(whole.substr(0, whole.size() / 2)).empty());
    CHECK(readableFunctionName("_ZN8psc_game12group_5_L149ERNS_3EnvERNS_4TurnE") == "group_5_L149");
    CHECK(readableFunctionName("psc_run_kernel") == "psc_run_kernel");
}

TEST_CASE("the stack bound is the heaviest chain of calls from a kernel, a cycle kMaxTurnNesting times", "[cuda]") {
    // k calls a (which calls b) and c; b and d call each other; e is never called.
    const std::vector<std::string> ptx = {
        ".visible .entry k(\n.param .u64 p\n)\n{\n\tcall.uni \n\ta, \n\t(\n\tparam0\n\t);\n"
        "\tcall.uni (retval0), \n\tc, \n\t(\n\t);\n}\n"
        ".func a(\n)\n{\n\tcall.uni \n\tb, \n\t(\n\t);\n}\n",
        ".visible .func  (.param .b32 func_retval0) b(\n)\n{\n\tcall.uni \n\td, \n\t(\n\t);\n}\n"
        ".weak .func d(\n)\n{\n\tcall.uni \n\tb, \n\t(\n\t);\n}\n"
        ".func c(\n)\n{\n\tret;\n}\n.func e(\n)\n{\n\tret;\n}\n"};
    auto frame = [](const char* f, int bytes) {
        return std::string("ptxas info    : Function properties for ") + f + "\nptxas         .     " + std::to_string(bytes) +
               " bytes stack frame, 0 bytes spill stores, 0 bytes spill loads\n";
    };
    const std::string log = frame("k", 100) + frame("a", 10) + frame("b", 1000) + frame("d", 300) + frame("c", 2000) +
                            frame("e", 50000) + frame("b", 900);
    // k + max(a + the cycle {b, d} gone round kMaxTurnNesting times, c).
    CHECK(stackBound(log, ptx) == 100 + 10 + kMaxTurnNesting * 1300 + kStackMargin);
    // With c heavier, the path to c is the heaviest.
    const std::string heavier = frame("k", 100) + frame("a", 10) + frame("b", 1000) + frame("d", 300) + frame("c", 9000);
    CHECK(stackBound(heavier, ptx) == 100 + 9000 + kStackMargin);
    CHECK(stackBound("", {}) == kStackMargin);
    // A function that calls itself is a cycle too.
    const std::vector<std::string> selfCall = {".visible .entry k(\n)\n{\n\tcall.uni \n\tf, \n\t(\n\t);\n}\n"
                                               ".func f(\n)\n{\n\tcall.uni \n\tf, \n\t(\n\t);\n}\n"};
    CHECK(stackBound(frame("k", 10) + frame("f", 100), selfCall) == 10 + kMaxTurnNesting * 100 + kStackMargin);
}

// The stack bound counts a cycle's frames kMaxTurnNesting times; the
// generated code allocates that many turns' scratch and traps past it.
TEST_CASE("the stack bound assumes the turn nesting the generated code allows", "[cuda]") {
    const std::string declaration = "constexpr int kMaxTurnNesting = " + std::to_string(kMaxTurnNesting) + ";";
    CHECK(codegen::templates::core().find(declaration) != std::string::npos);
}
