// Fuzz target (b): the front end and the code generator (`psc --emit cpp`
// in both rule forms, and the CUDA source) on every game the front end
// accepts.  With
// PSC_FUZZ_COMPILE_EVERY=N, one accepted input in N (chosen by its hash, so a
// reproduction checks it again) has its generated C++ checked by the system
// compiler (-fsyntax-only): a source that does not compile is a crash.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <string_view>

#include "ChildProcess.h"
#include "Compiler.h"
#include "CppSource.h"
#include "GameMutator.h"
#include "base/Sha1.h"

namespace {

void checkCompiles(const std::string& source, const std::string& key) {
    const std::string path = "/tmp/psc-fuzz-codegen-" + key + ".cpp";
    {
        std::ofstream out(path, std::ios::binary);
        out << source;
    }
    const std::string log = path + ".log";
    const psc::ChildResult r = psc::runChild({"c++", "-std=c++17", "-fsyntax-only", "-w", path}, log, psc::defaultCompileLimits());
    if (!r.ok()) {
        std::fprintf(stderr, "codegen_fuzzer: the generated source %s does not compile (log: %s)\n", path.c_str(), log.c_str());
        std::abort();
    }
    std::remove(path.c_str());
    std::remove(log.c_str());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    psc::CompileResult result = psc::compileSource(text);
    if (!result.game || !result.playable()) return 0;
    psc::codegen::SourceOptions so;
    so.sourceName = "fuzz.txt";
    so.sourceSha1 = psc::sha1Hex(text);
    const std::string cpu = psc::codegen::cpuPluginSource(*result.game, so);
    so.ruleForm = "table";
    const std::string cpuTable = psc::codegen::cpuPluginSource(*result.game, so);
    so.ruleForm = "auto";
    so.target = "cuda";
    psc::codegen::cudaSource(*result.game, so);
    static const long every = [] {
        const char* e = std::getenv("PSC_FUZZ_COMPILE_EVERY");
        return e ? std::atol(e) : 0L;
    }();
    if (every > 0 && std::stoul(so.sourceSha1.substr(0, 8), nullptr, 16) % static_cast<unsigned long>(every) == 0) {
        checkCompiles(cpu, so.sourceSha1);
        checkCompiles(cpuTable, so.sourceSha1 + "-table");
    }
    return 0;
}

extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t maxSize, unsigned int seed) {
    return psc::fuzz::mutateGameBytes(data, size, maxSize, seed);
}
