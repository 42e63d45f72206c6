// The named colours of PuzzleScript and its selectable palettes.
#pragma once

#include <optional>
#include <string>

namespace psc::palette {

inline constexpr const char* kDefaultPalette = "arnecolors";

// A colour a sprite may use: a palette colour name, "transparent", or #rgb / #rrggbb.
bool isColor(const std::string& color);
// The palette named by a color_palette value (a name or its number), if any.
std::optional<std::string> resolve(const std::string& value);
// A colour as "#rrggbb" (lower case) in the given palette; "transparent" and
// unknown text are returned as they are.
std::string toHex(const std::string& palette, const std::string& color);

}  // namespace psc::palette
