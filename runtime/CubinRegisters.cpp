#include "CubinRegisters.h"

#include <cxxabi.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>

namespace psc {

namespace {

// A bounds-checked little-endian view of the file.
struct Bytes {
    std::string_view data;

    template <typename T>
    std::optional<T> read(uint64_t offset) const {
        if (offset > data.size() || data.size() - offset < sizeof(T)) return std::nullopt;
        T value;
        std::memcpy(&value, data.data() + offset, sizeof(T));
        return value;
    }
    std::string string(uint64_t offset) const {
        if (offset >= data.size()) return {};
        const size_t end = data.find('\0', offset);
        return std::string(data.substr(offset, end == std::string_view::npos ? std::string_view::npos : end - offset));
    }
};

struct Section {
    uint32_t name;
    uint32_t type;
    uint64_t offset;
    uint64_t size;
    uint32_t link;
};

constexpr uint32_t kSymbolTable = 2;         // SHT_SYMTAB
constexpr uint8_t kFunctionSymbol = 2;       // STT_FUNC
constexpr uint8_t kCudaEntry = 0x10;         // st_other's STO_CUDA_ENTRY: a kernel
constexpr uint8_t kAttributeFormatSized = 4;  // EIFMT_SVAL: a 16-bit size, then that many bytes
constexpr uint8_t kAttributeFormatHalf = 3;  // EIFMT_HVAL: a 16-bit value
constexpr uint8_t kRegisterCount = 0x2f;     // EIATTR_REGCOUNT: symbol index, registers

std::optional<std::vector<Section>> sections(const Bytes& in) {
    if (in.data.size() < 64 || in.data.substr(0, 4) != "\x7f" "ELF" || in.data[4] != 2 /* ELFCLASS64 */) {
        return std::nullopt;
    }
    const auto table = in.read<uint64_t>(0x28);
    const auto entrySize = in.read<uint16_t>(0x3a);
    const auto count = in.read<uint16_t>(0x3c);
    if (!table || !entrySize || !count || *entrySize < 64) return std::nullopt;
    std::vector<Section> out;
    for (uint16_t i = 0; i < *count; ++i) {
        const uint64_t at = *table + static_cast<uint64_t>(i) * *entrySize;
        const auto name = in.read<uint32_t>(at);
        const auto type = in.read<uint32_t>(at + 4);
        const auto offset = in.read<uint64_t>(at + 24);
        const auto size = in.read<uint64_t>(at + 32);
        const auto link = in.read<uint32_t>(at + 40);
        if (!name || !type || !offset || !size || !link) return std::nullopt;
        if (*offset > in.data.size() || in.data.size() - *offset < *size) return std::nullopt;
        out.push_back({*name, *type, *offset, *size, *link});
    }
    return out;
}

}  // namespace

std::vector<FunctionRegisters> cubinRegisters(std::string_view cubin) {
    const Bytes in{cubin};
    const auto all = sections(in);
    const auto namesIndex = in.read<uint16_t>(0x3e);
    if (!all || !namesIndex || *namesIndex >= all->size()) return {};
    const Section& sectionNames = (*all)[*namesIndex];
    const auto symbolTable = std::find_if(all->begin(), all->end(), [](const Section& s) { return s.type == kSymbolTable; });
    if (symbolTable == all->end() || symbolTable->link >= all->size()) return {};
    const Section& symbolNames = (*all)[symbolTable->link];

    struct Symbol {
        std::string name;
        bool function;
        bool kernel;
    };
    std::vector<Symbol> symbols;
    for (uint64_t at = symbolTable->offset; at + 24 <= symbolTable->offset + symbolTable->size; at += 24) {
        const uint32_t name = *in.read<uint32_t>(at);
        const uint8_t info = *in.read<uint8_t>(at + 4);
        const uint8_t other = *in.read<uint8_t>(at + 5);
        symbols.push_back({name < symbolNames.size ? in.string(symbolNames.offset + name) : std::string(),
                           (info & 0xf) == kFunctionSymbol, (other & kCudaEntry) != 0});
    }

    std::map<std::string, FunctionRegisters> found;
    for (const Section& s : *all) {
        if (s.name >= sectionNames.size || in.string(sectionNames.offset + s.name).rfind(".nv.info", 0) != 0) continue;
        for (uint64_t at = s.offset; at + 2 <= s.offset + s.size;) {
            const uint8_t format = *in.read<uint8_t>(at);
            const uint8_t attribute = *in.read<uint8_t>(at + 1);
            uint64_t value = at + 2;
            uint64_t length = 0;
            if (format == kAttributeFormatSized) {
                const auto size = in.read<uint16_t>(at + 2);
                if (!size) break;
                value = at + 4;
                length = *size;
            } else if (format == kAttributeFormatHalf) {
                length = 2;
            }
            if (value + length > s.offset + s.size) break;
            if (attribute == kRegisterCount && format == kAttributeFormatSized && length == 8) {
                const uint32_t symbol = *in.read<uint32_t>(value);
                const uint32_t registers = *in.read<uint32_t>(value + 4);
                if (symbol < symbols.size() && symbols[symbol].function && !symbols[symbol].name.empty()) {
                    const Symbol& f = symbols[symbol];
                    found[f.name] = {f.name, static_cast<int>(registers), f.kernel};
                }
            }
            at = value + length;
        }
    }
    std::vector<FunctionRegisters> out;
    for (auto& [name, f] : found) out.push_back(std::move(f));
    std::stable_sort(out.begin(), out.end(),
                     [](const FunctionRegisters& a, const FunctionRegisters& b) { return a.registers > b.registers; });
    return out;
}

std::string readableFunctionName(const std::string& symbol) {
    int status = 0;
    char* demangled = abi::__cxa_demangle(symbol.c_str(), nullptr, nullptr, &status);
    std::string name = status == 0 && demangled ? demangled : symbol;
    std::free(demangled);
    if (const size_t open = name.find('('); open != std::string::npos) name.resize(open);
    const std::string_view space = "psc_game::";
    if (name.rfind(space, 0) == 0) name.erase(0, space.size());
    return name;
}

}  // namespace psc
