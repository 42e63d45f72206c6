// What a cubin's ELF says of the registers a thread each of its functions
// takes (the .nv.info sections' EIATTR_REGCOUNT).  Linked from separately
// compiled units, a kernel takes the most registers of any function it may
// call, and that count sets how many of its warps an SM holds: --verbose
// names the functions that set it (cli/GameBuild.cpp).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace psc {

struct FunctionRegisters {
    std::string name;  // as the cubin's symbol table spells it (mangled)
    int registers = 0;
    bool kernel = false;
};

// Every function the cubin gives a register count, most registers first (by
// name among equals); empty when `cubin` is not an ELF64 file it can read
// through (a truncated or foreign file is read no further than its bounds).
std::vector<FunctionRegisters> cubinRegisters(std::string_view cubin);

// A function's name for people: demangled, without its parameters and the
// psc_game:: namespace (_ZN8psc_game12group_5_L149ERNS_3EnvERNS_4TurnE ->
// group_5_L149).
std::string readableFunctionName(const std::string& symbol);

}  // namespace psc
