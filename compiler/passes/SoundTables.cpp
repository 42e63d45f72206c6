#include "passes/SoundTables.h"

namespace psc::passes {
namespace {

using Kind = ast::SoundWord::Kind;

int soundDirectionMask(const std::string& d) {
    if (d == "up") return 1;
    if (d == "down") return 2;
    if (d == "left") return 4;
    if (d == "right") return 8;
    if (d == "horizontal") return 12;
    if (d == "vertical") return 3;
    if (d == "orthogonal") return 15;
    if (d == "action") return 16;
    return -1;
}

// The objects a sound target stands for: synonyms followed, properties spread.
std::vector<std::string> soundTargets(CompileState& st, const std::string& target) {
    std::vector<std::string> targets = {target};
    bool modified = true;
    for (int round = 0; modified; ++round) {
        if (round > 10000) throw CompileAborted("sound target names refer to each other in a cycle");
        modified = false;
        for (size_t k = 0; k < targets.size(); ++k) {
            if (const std::string* syn = st.synonyms.find(targets[k])) {
                targets[k] = *syn;
                modified = true;
            } else if (const Members* members = st.properties.find(targets[k])) {
                modified = true;
                std::vector<std::string> add = **members;
                targets.erase(targets.begin() + static_cast<long>(k));
                --k;
                targets.insert(targets.end(), add.begin(), add.end());
            }
        }
    }
    return targets;
}

}  // namespace

void buildSoundTables(CompileState& st) {
    ir::Sounds& sounds = st.ir.sounds;
    sounds.move.assign(static_cast<size_t>(st.layerCount()), {});
    for (const ast::SoundDecl& decl : st.ast.sounds) {
        const auto& w = decl.words;
        const int line = decl.line;
        if (w.empty()) continue;
        if (w.size() == 1) {
            st.diag.warning(line, "incomplete sound declaration");
            continue;
        }
        const std::string& seed = w.back().text;
        if (w.back().kind != Kind::Seed) st.diag.error(line, "expected a sound seed, found \"" + seed + "\"");
        if (w[0].kind == Kind::Event) {
            if (w.size() > 3) st.diag.error(line, "too many words for a sound event");
            else if (w.size() > 2) st.diag.warning(line, "too many words for a sound event");
            if (sounds.events.count(w[0].text)) st.diag.warning(line, js::toUpperAscii(w[0].text) + " is already declared");
            sounds.events[w[0].text] = seed;
            continue;
        }
        const std::string& target = w[0].text;
        std::string verb = w[1].text;
        std::vector<std::string> directions;
        for (size_t j = 2; j + 1 < w.size(); ++j) {
            if (w[j].kind == Kind::Direction) directions.push_back(w[j].text);
            else st.diag.error(line, "expected a direction, found \"" + w[j].text + "\"");
        }
        if (!directions.empty() && verb != "move" && verb != "cantmove") {
            st.diag.error(line, "only MOVE and CANTMOVE sounds take directions");
        }
        if (verb == "action") {
            verb = "move";
            directions = {"action"};
        }
        if (directions.empty()) directions = {"orthogonal"};
        if (st.aggregates.has(target)) {
            st.diag.error(line, "sounds cannot be attached to the aggregate \"" + target +
                                    "\" (defined with AND), only to objects and properties");
            continue;
        }
        const BitSet* objectMask = st.objectMasks.find(target);
        if (!objectMask) st.diag.error(line, "object \"" + target + "\" not found");
        int directionBits = 0;
        for (const auto& d : directions) {
            int bits = soundDirectionMask(d);
            if (bits < 0) st.diag.error(line, "expected a direction, found \"" + d + "\"");
            else directionBits |= bits;
        }
        if (verb == "move" || verb == "cantmove") {
            for (const std::string& name : soundTargets(st, target)) {
                const ObjectInfo* o = st.object(name);
                if (!o || !o->layer) continue;
                ir::MoveSound s{*o->layer, *o->id, directionBits, seed};
                if (verb == "move") sounds.move[static_cast<size_t>(*o->layer)].push_back(s);
                else sounds.cantMove.push_back(s);
            }
        }
        if (verb == "create" || verb == "destroy") {
            ir::ObjectSound s{objectMask ? *objectMask : BitSet(), seed};
            (verb == "create" ? sounds.create : sounds.destroy).push_back(s);
        }
    }
}

}  // namespace psc::passes
