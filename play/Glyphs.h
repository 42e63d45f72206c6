// Level glyphs for a cell's objects, for drawing a level as text.  The
// plugin knows no legend, so the table is made from the compiled game: the
// legend glyph that stands for exactly a cell's objects (background objects
// aside when no glyph names them), in the case the source wrote it; for sets
// no glyph stands for, the glyph of the cell's topmost object, else that
// object's initial.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "Compiler.h"
#include "psc_plugin.h"

namespace psc::play {

class GlyphTable {
public:
    GlyphTable() = default;
    // `channels` names the plugin's observation channels (game_info).
    GlyphTable(const ast::Game& ast, const ir::Game& game, const std::string& sourceText, const psc_game_info& info);

    // The glyph (one UTF-8 character of width 1) for a cell holding these
    // channels, in channel order.
    const std::string& glyph(const std::vector<int>& channels) const;
    // What a glyph shows, for a key under the level: "crate+target".
    std::string describe(const std::vector<int>& channels) const;

private:
    std::vector<int> withoutBackground(const std::vector<int>& channels) const;
    std::string generated(const std::vector<int>& channels) const;

    std::vector<std::string> channelNames_;
    std::vector<bool> backgroundChannel_;
    std::map<std::vector<int>, std::string> exact_;
    std::map<std::vector<int>, std::string> foreground_;  // by the set without background objects
    mutable std::map<std::vector<int>, std::string> cache_;
};

}  // namespace psc::play
