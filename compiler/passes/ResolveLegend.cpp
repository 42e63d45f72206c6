#include "passes/ResolveLegend.h"

#include <algorithm>

#include "base/Palettes.h"

namespace psc::passes {
namespace {

using js::toUpperAscii;

// The reference loops until its legend tables stop changing; some erroneous
// games never settle there (it hangs).  psc gives up instead.
constexpr int kMaxLegendRounds = 10000;

void assignIds(CompileState& st) {
    for (const auto& decl : st.ast.objects) st.objects.set(decl.name, ObjectInfo{std::nullopt, std::nullopt, decl.line});
    int next = 0;
    for (int layer = 0; layer < st.layerCount(); ++layer) {
        for (const std::string& name : st.ast.collisionLayers[layer]) {
            ObjectInfo* o = st.objects.find(name);
            if (!o) continue;
            o->layer = layer;
            o->id = next++;
            st.idNames.push_back(name);
        }
    }
    st.ir.objectCount = next;
    st.ir.layerCount = st.layerCount();
    st.objectBits = static_cast<size_t>(next);
}

std::string choosePalette(CompileState& st) {
    std::string palette = palette::kDefaultPalette;
    for (const auto& m : st.ast.metadata) {
        if (m.key != "color_palette") continue;
        if (auto resolved = palette::resolve(m.value)) palette = *resolved;
        else st.diag.error(0, "unknown colour palette \"" + m.value + "\"; using arnecolors");
    }
    return palette;
}

void resolveObjectGraphics(CompileState& st, const std::string& palette) {
    for (const std::string& name : st.objects.keys()) {
        const ast::ObjectDecl& decl = *st.ast.findObject(name);
        if (decl.colors.size() > 10) st.diag.error(decl.line + 1, "an object can have at most 10 colours");
        std::vector<std::string> colors;
        for (const std::string& c : decl.colors) {
            if (palette::isColor(c)) {
                colors.push_back(palette::toHex(palette, c));
            } else {
                st.diag.error(decl.line + 1, "invalid colour \"" + c + "\" for object " + toUpperAscii(name));
                colors.push_back("#ff00ff");
            }
        }
        if (colors.empty()) {
            st.diag.error(decl.line, "no colour given for object " + toUpperAscii(name));
            colors.push_back("#ff00ff");
        }
        std::vector<std::vector<int>> sprite;
        if (decl.spriteRows.empty()) {
            sprite.assign(5, std::vector<int>(5, 0));
        } else {
            bool square = decl.spriteRows.size() == 5;
            for (const auto& row : decl.spriteRows) square = square && row.size() == 5;
            if (!square) st.diag.warning(decl.line, "sprites must be 5 pixels wide and 5 high");
            // The reference reads an n-row sprite as n x n (padding short rows).
            size_t n = decl.spriteRows.size();
            for (const auto& row : decl.spriteRows) {
                std::vector<int> pixels;
                for (size_t j = 0; j < n; ++j) {
                    char ch = j < row.size() ? row[j] : '\0';
                    pixels.push_back(ch == '.' ? -1 : (ch >= '0' && ch <= '9') ? ch - '0' : -2);
                }
                sprite.push_back(std::move(pixels));
            }
        }
        const ObjectInfo& info = st.objects.at(name);
        if (info.id) {
            ir::Object& o = st.ir.objects[static_cast<size_t>(*info.id)];
            o.colors = colors;
            o.sprite = sprite;
            o.line = decl.line;
        }
    }
}

void buildObjectTable(CompileState& st) {
    st.ir.objects.resize(static_cast<size_t>(st.ir.objectCount));
    for (int id = 0; id < st.ir.objectCount; ++id) {
        ir::Object& o = st.ir.objects[static_cast<size_t>(id)];
        o.id = id;
        o.name = st.idNames[static_cast<size_t>(id)];
        const ObjectInfo& info = st.objects.at(o.name);
        if (info.id == id) {
            o.layer = info.layer;
        } else {
            o.ghost = true;
            o.liveId = info.id;
        }
    }
    // Ghosts: the layer of the listing that created them.
    int id = 0;
    for (int layer = 0; layer < st.layerCount(); ++layer) {
        for (const std::string& name : st.ast.collisionLayers[layer]) {
            if (!st.objects.has(name)) continue;
            if (st.ir.objects[static_cast<size_t>(id)].ghost) st.ir.objects[static_cast<size_t>(id)].listedInLayer = layer;
            ++id;
        }
    }
    for (const std::string& name : st.objects.keys()) {
        if (!st.objects.at(name).layer) st.ir.unlayeredObjects.push_back(name);
    }
}

void buildGlyphs(CompileState& st) {
    const std::vector<int> blank(static_cast<size_t>(st.layerCount()), -1);
    for (const std::string& name : st.objects.keys()) {
        const ObjectInfo& o = st.objects.at(name);
        std::vector<int> mask = blank;
        if (o.layer) mask[static_cast<size_t>(*o.layer)] = *o.id;
        st.glyphs.set(name, mask);
    }
    bool added = true;
    while (added) {
        added = false;
        for (const auto& syn : st.ast.synonyms) {
            const std::string& target = syn.members[0];
            if (!st.glyphs.has(syn.name) && st.glyphs.has(target)) {
                added = true;
                st.glyphs.set(syn.name, st.glyphs.at(target));
            }
        }
        for (const auto& agg : st.ast.aggregates) {
            bool allKnown = std::all_of(agg.members.begin(), agg.members.end(),
                                        [&](const std::string& m) { return st.glyphs.has(m); });
            if (st.glyphs.has(agg.name) || !allKnown) continue;
            std::vector<int> mask = blank;
            for (const std::string& part : agg.members) {
                const ObjectInfo* o = st.object(part);
                if (!o) throw CompileAborted("aggregate " + agg.name + " has a part that is not an object");
                if (o->layer && mask[static_cast<size_t>(*o->layer)] == -1) {
                    mask[static_cast<size_t>(*o->layer)] = *o->id;
                } else if (!o->layer) {
                    st.diag.error(agg.line, "object " + toUpperAscii(part) + " is defined but in no collision layer");
                } else {
                    std::string other = st.idNames[static_cast<size_t>(mask[static_cast<size_t>(*o->layer)])];
                    st.diag.error(agg.line, "aggregate " + toUpperAscii(agg.name) + " combines " + toUpperAscii(part) +
                                                " and " + toUpperAscii(other) +
                                                ", which share a collision layer and cannot coexist");
                }
            }
            added = true;
            st.glyphs.set(agg.name, mask);
        }
    }
}

// Substitutes synonyms and splices in same-kind entries; returns whether anything changed.
bool expandEntries(CompileState& st, JsObject<Members>& dict, const JsObject<Members>& conflicting,
                   const char* kind, const char* conflictingKind) {
    bool modified = false;
    for (const std::string& n : dict.keys()) {
        Members values = dict.at(n);
        for (size_t i = 0; i < values->size(); ++i) {
            std::string value = (*values)[i];
            if (const std::string* syn = st.synonyms.find(value)) {
                (*values)[i] = *syn;
                modified = true;
            } else if (const Members* other = dict.find(value)) {
                Members source = *other;
                values->erase(values->begin() + static_cast<long>(i));
                std::vector<std::string> newValues = *source;
                for (const std::string& v : newValues) {
                    if (std::find(values->begin(), values->end(), v) == values->end()) values->push_back(v);
                }
                modified = true;
            }
            if (conflicting.has(value)) {
                st.diag.error(std::nullopt, std::string(kind) + " " + toUpperAscii(n) + " is defined in terms of the " +
                                                conflictingKind + " " + toUpperAscii(value));
            }
        }
    }
    return modified;
}

void buildDictionaries(CompileState& st) {
    for (const auto& agg : st.ast.aggregates) st.aggregates.set(agg.name, std::make_shared<std::vector<std::string>>(agg.members));
    for (const auto& prop : st.ast.properties) st.properties.set(prop.name, std::make_shared<std::vector<std::string>>(prop.members));
    for (const auto& syn : st.ast.synonyms) {
        const std::string& key = syn.name;
        const std::string& value = syn.members[0];
        if (const Members* a = st.aggregates.find(value)) st.aggregates.set(key, *a);
        else if (const Members* p = st.properties.find(value)) st.properties.set(key, *p);
        else if (key != value) st.synonyms.set(key, value);
    }
    bool modified = true;
    for (int round = 0; modified; ++round) {
        if (round > kMaxLegendRounds) throw CompileAborted("legend definitions never settle (a cycle through an undefined name)");
        modified = false;
        for (const std::string& n : st.synonyms.keys()) {
            const std::string* valuePtr = st.synonyms.find(n);
            if (!valuePtr) continue;
            std::string value = *valuePtr;
            if (const Members* p = st.properties.find(value)) {
                Members shared = *p;
                st.synonyms.erase(n);
                st.properties.set(n, shared);
                modified = true;
            } else if (const Members* a = st.aggregates.find(value)) {
                // The reference deletes the aggregate entry here, not the synonym.
                Members shared = *a;
                st.aggregates.erase(n);
                st.aggregates.set(n, shared);
                modified = true;
            } else if (const std::string* next = st.synonyms.find(value)) {
                std::string target = *next;
                st.synonyms.set(n, target);
            }
        }
        modified = expandEntries(st, st.properties, st.aggregates, "property", "aggregate") || modified;
        modified = expandEntries(st, st.aggregates, st.properties, "aggregate", "property") || modified;
    }
}

void findSingleLayerProperties(CompileState& st) {
    for (const std::string& key : st.properties.keys()) {
        const auto& values = *st.properties.at(key);
        bool sameLayer = true;
        for (size_t i = 0; i < values.size(); ++i) {
            const ObjectInfo* o = st.object(values[i]);
            if (!o) {
                sameLayer = false;
                break;
            }
            if (i > 0 && o->layer != st.object(values[i - 1])->layer) {
                sameLayer = false;
                break;
            }
        }
        if (sameLayer && !values.empty()) {
            const ObjectInfo* first = st.object(values[0]);
            if (first) st.singleLayerProperties.set(key, first->layer);
        }
    }
}

void chooseBackground(CompileState& st) {
    auto useObject = [&](const ObjectInfo* o) {
        if (!o) return;
        st.backgroundId = o->id;
        st.backgroundLayer = o->layer;
    };
    auto firstObject = [&]() -> const ObjectInfo* {
        return st.idNames.empty() ? nullptr : st.object(st.idNames[0]);
    };
    std::optional<int> backgroundLine;
    if (auto it = st.ast.nameLines.find("background"); it != st.ast.nameLines.end()) backgroundLine = it->second;

    if (const ObjectInfo* bg = st.object("background")) {
        useObject(bg);
    } else if (const std::string* target = st.synonyms.find("background")) {
        const ObjectInfo* o = st.object(*target);
        if (!o) throw CompileAborted("BACKGROUND names something that is not an object");
        useObject(o);
    } else if (const Members* members = st.properties.find("background")) {
        const ObjectInfo* o = (*members)->empty() ? nullptr : st.object((*members)->front());
        if (o) {
            useObject(o);
            for (size_t i = 1; i < (*members)->size(); ++i) {
                const ObjectInfo* other = st.object((**members)[i]);
                if (other && other->layer != st.backgroundLayer) {
                    st.diag.error(backgroundLine, "the objects of BACKGROUND must share one collision layer");
                }
            }
        }
    } else if (st.aggregates.has("background")) {
        useObject(firstObject());
        st.diag.error(backgroundLine, "BACKGROUND cannot be an aggregate (defined with AND); use an object or a "
                                      "property (defined with OR)");
    } else {
        useObject(firstObject());
        st.diag.error(std::nullopt, "the game has no BACKGROUND object");
    }
    if (st.backgroundId && st.backgroundLayer) st.ir.background = ir::Background{*st.backgroundId, *st.backgroundLayer};
}

}  // namespace

void resolveLegend(CompileState& st) {
    assignIds(st);
    buildObjectTable(st);
    std::string palette = choosePalette(st);
    resolveObjectGraphics(st, palette);
    buildGlyphs(st);
    buildDictionaries(st);
    findSingleLayerProperties(st);
    if (st.idNames.empty() && st.layerCount() > 0) st.diag.error(std::nullopt, "the game defines no objects");
    chooseBackground(st);

    ir::Legend& legend = st.ir.legend;
    for (const std::string& k : st.synonyms.keys()) legend.synonyms[k] = st.synonyms.at(k);
    for (const std::string& k : st.properties.keys()) legend.properties[k] = *st.properties.at(k);
    for (const std::string& k : st.aggregates.keys()) legend.aggregates[k] = *st.aggregates.at(k);
    for (const std::string& k : st.singleLayerProperties.keys()) {
        if (auto layer = st.singleLayerProperties.at(k)) legend.singleLayerProperties[k] = *layer;
    }
    for (const std::string& k : st.glyphs.keys()) {
        std::vector<int> ids;
        for (int id : st.glyphs.at(k)) {
            if (id >= 0) ids.push_back(id);
        }
        legend.glyphs[k] = ids;
    }
}

}  // namespace psc::passes
