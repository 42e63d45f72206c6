#include "passes/BuildLevels.h"

#include <unordered_map>

namespace psc::passes {
namespace {

BitSet backgroundFill(CompileState& st, const ir::Level& level) {
    BitSet fill(st.objectBits);
    if (!st.backgroundLayer || static_cast<size_t>(*st.backgroundLayer) >= st.layerMasks.size()) {
        st.diag.error(std::nullopt, "the game has no background layer");
        if (st.backgroundId) fill.set(static_cast<size_t>(*st.backgroundId));
        return fill;
    }
    const BitSet& backgroundMask = st.layerMasks[static_cast<size_t>(*st.backgroundLayer)];
    for (const BitSet& cell : level.cells) {
        BitSet onLayer = cell;
        onLayer &= backgroundMask;
        if (onLayer.any()) return onLayer;
    }
    if (st.backgroundId && st.objectBits > 0) fill.set(static_cast<size_t>(*st.backgroundId));
    return fill;
}

ir::Level buildLevel(CompileState& st, const ast::LevelSource& src) {
    ir::Level level;
    level.line = src.line;
    const size_t width = src.rows.front().size();
    const size_t height = src.rows.size();
    if (width * height > kMaxLevelCells) {
        st.diag.error(src.line, "this level has " + std::to_string(width) + " x " + std::to_string(height) +
                                    " cells; psc supports at most " + std::to_string(kMaxLevelCells));
        st.invalid = true;
        return level;
    }
    level.width = static_cast<int>(width);
    level.height = static_cast<int>(height);
    level.cells.assign(static_cast<size_t>(level.width) * static_cast<size_t>(level.height), BitSet(st.objectBits));
    std::unordered_map<char16_t, BitSet> glyphCache;
    for (int x = 0; x < level.width; ++x) {
        for (int y = 0; y < level.height; ++y) {
            const std::u16string& row = src.rows[static_cast<size_t>(y)];
            std::u16string glyph;
            if (static_cast<size_t>(x) < row.size()) glyph = row.substr(static_cast<size_t>(x), 1);
            else if (!row.empty()) glyph = row.substr(row.size() - 1, 1);
            std::string key = js::toUtf8(glyph);
            const std::vector<int>* ids = st.glyphs.find(key);
            if (!ids) {
                if (!st.properties.has(key)) {
                    st.diag.error(src.line + y, "level glyph \"" + key + "\" is not defined in the legend");
                } else {
                    st.diag.error(src.line + y, "level glyph \"" + key + "\" is a property (defined with OR), so it "
                                                "is ambiguous in a map; define it with AND instead?");
                }
                return level;
            }
            BitSet cell(st.objectBits);
            for (int id : *ids) {
                if (id >= 0) cell.set(static_cast<size_t>(id));
            }
            level.cells[static_cast<size_t>(x * level.height + y)] = cell;
        }
    }
    BitSet fill = backgroundFill(st, level);
    const BitSet* backgroundMask = (st.backgroundLayer && static_cast<size_t>(*st.backgroundLayer) < st.layerMasks.size())
                                       ? &st.layerMasks[static_cast<size_t>(*st.backgroundLayer)]
                                       : nullptr;
    for (BitSet& cell : level.cells) {
        if (!backgroundMask || !backgroundMask->intersects(cell)) cell |= fill;
    }
    return level;
}

}  // namespace

void buildLevels(CompileState& st) {
    for (const ast::LevelSource& src : st.ast.levels) {
        if (src.isMessage) {
            ir::Level message;
            message.isMessage = true;
            message.message = src.message;
            message.line = src.line;
            st.ir.levels.push_back(std::move(message));
        } else if (!src.rows.empty()) {
            st.ir.levels.push_back(buildLevel(st, src));
        }
    }
}

}  // namespace psc::passes
