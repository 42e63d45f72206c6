#include "base/Palettes.h"

#include <cctype>
#include <iterator>

namespace psc::palette {
namespace {

#include "base/Palettes.inc"

const PaletteData* find(const std::string& name) {
    for (const PaletteData& p : kPalettes) {
        if (name == p.name) return &p;
    }
    return nullptr;
}

int colorIndex(const std::string& color) {
    for (size_t i = 0; i < std::size(kColorNames); ++i) {
        if (color == kColorNames[i]) return static_cast<int>(i);
    }
    return -1;
}

bool isHexColor(const std::string& c) {
    if (c.size() != 4 && c.size() != 7) return false;
    if (c[0] != '#') return false;
    for (size_t i = 1; i < c.size(); ++i) {
        if (!std::isxdigit(static_cast<unsigned char>(c[i]))) return false;
    }
    return true;
}

}  // namespace

bool isColor(const std::string& color) { return colorIndex(color) >= 0 || isHexColor(color) || color == "transparent"; }

std::optional<std::string> resolve(const std::string& value) {
    for (const PaletteData& p : kPalettes) {
        if (value == p.name || (p.alias > 0 && value == std::to_string(p.alias))) return std::string(p.name);
    }
    return std::nullopt;
}

std::string toHex(const std::string& palette, const std::string& color) {
    const PaletteData* p = find(palette);
    int index = colorIndex(color);
    if (p && index >= 0) return p->hex[index];
    return color;
}

}  // namespace psc::palette
