#include "RuleTable.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <map>

#include "RuleCode.h"
#include "RuleParts.h"
#include "ir/IrDump.h"

namespace psc::codegen {
namespace {

using ir::CellPattern;
using ir::Game;
using ir::Rule;

// templates/rule_table.h's direction codes: the straight-line form's steps
// +1, -1, +(H+1), -(H+1).
int directionCode(int direction) {
    switch (direction) {
        case ir::kUp: return 1;
        case ir::kRight: return 2;
        case ir::kLeft: return 3;
        default: return 0;
    }
}

// A board reference: object id, or -(movement bit) - 1.
int movementRef(size_t bit) { return -static_cast<int>(bit) - 1; }

// Writes records into one table; identical cell, replacement and row
// records are written once and shared (a rule expanded over a property's
// objects repeats most of its cells).
class TableWriter {
public:
    TableWriter(const Game& g, std::vector<std::string> messages)
        : g_(g), messages_(std::move(messages)), layersExclusive_(layersHoldOneObject(g)) {}

    // Appends a rule's records; returns its offset.
    int addRule(const Rule& rule) {
        const int flags = (rule.hasReplacements ? 1 : 0) | (hasEllipsis(rule) ? 2 : 0);
        std::vector<int> record = {directionCode(rule.direction), flags, static_cast<int>(commandBits(rule)),
                                   messageIndex(rule, messages_), rigidGroupClaim(g_, rule),
                                   static_cast<int>(rule.rows.size())};
        for (size_t r = 0; r < rule.rows.size(); ++r) record.push_back(addRow(rule, r));
        maxRows_ = std::max(maxRows_, static_cast<int>(rule.rows.size()));
        int saved = 0;
        for (const auto& row : rule.rows) {
            bool afterEllipsis = false;
            for (const auto& c : row) {
                afterEllipsis = afterEllipsis || c.ellipsis;
                saved += afterEllipsis && !c.ellipsis ? 1 : 0;
            }
        }
        maxSaved_ = std::max(maxSaved_, saved);
        const int at = size();
        data_.insert(data_.end(), record.begin(), record.end());
        return at;
    }

    const std::vector<int>& data() const { return data_; }
    int maxRows() const { return std::max(1, maxRows_); }
    int maxSavedCells() const { return std::max(1, maxSaved_); }

private:
    int size() const { return static_cast<int>(data_.size()); }

    // The offset of a record with these numbers, written now unless it was before.
    int shared(const std::vector<int>& record) {
        auto [it, added] = written_.try_emplace(record, size());
        if (added) data_.insert(data_.end(), record.begin(), record.end());
        return it->second;
    }

    int addRow(const Rule& rule, size_t index) {
        const std::vector<CellPattern>& cells = rule.rows[index];
        std::vector<int> ellipses;
        for (size_t i = 0; i < cells.size(); ++i) {
            if (cells[i].ellipsis) ellipses.push_back(static_cast<int>(i));
        }
        std::vector<int> record = {static_cast<int>(cells.size()), ellipses.empty() ? -1 : ellipses[0],
                                   ellipses.size() < 2 ? -1 : ellipses[1]};
        for (const auto& c : cells) {
            record.push_back(c.ellipsis ? -1 : addCell(rule, index, c));
        }
        return shared(record);
    }

    int addCell(const Rule& rule, size_t row, const CellPattern& c) {
        std::vector<std::vector<int>> terms;
        c.present.forEach([&](size_t id) { terms.push_back({static_cast<int>(id)}); });
        for (const auto& any : c.anyOf) terms.push_back(any.bits());
        c.movementsPresent.forEach([&](size_t bit) { terms.push_back({movementRef(bit)}); });
        std::vector<int> excluded = c.missing.bits();
        c.movementsMissing.forEach([&](size_t bit) { excluded.push_back(movementRef(bit)); });
        const std::optional<CellFacts> facts = knownFacts(g_, rule, row, c, layersExclusive_);
        std::vector<int> record = {c.replacement ? addReplacement(rule, *c.replacement, facts ? &*facts : nullptr) : -1,
                                   static_cast<int>(terms.size())};
        for (const auto& term : terms) {
            record.push_back(static_cast<int>(term.size()));
            record.insert(record.end(), term.begin(), term.end());
        }
        record.push_back(static_cast<int>(excluded.size()));
        record.insert(record.end(), excluded.begin(), excluded.end());
        return shared(record);
    }

    static void addUpdates(std::vector<int>& record, const std::vector<ObjectUpdate>& objects,
                           const std::vector<MovementUpdate>& movements) {
        record.push_back(static_cast<int>(objects.size()));
        for (const auto& u : objects) {
            record.insert(record.end(), {u.kind == ObjectUpdate::kPutLayer ? 0 : 1, u.layerOrObject, u.keepOrValue});
        }
        record.push_back(static_cast<int>(movements.size()));
        for (const auto& u : movements) {
            record.insert(record.end(), {u.layer, static_cast<int>(u.clear), static_cast<int>(u.set), u.randomDirection ? 1 : 0});
        }
    }

    int addReplacement(const Rule& rule, const ir::Replacement& r, const CellFacts* facts) {
        const std::vector<int> candidates = r.randomEntity.bits();
        std::vector<int> record = {static_cast<int>(candidates.size())};
        std::vector<int> randomDirections;
        for (int L = 0; L < g_.layerCount; ++L) {
            if (r.randomDirMask.test(static_cast<size_t>(5 * L))) randomDirections.push_back(L);
        }
        record.push_back(static_cast<int>(randomDirections.size()));
        record.insert(record.end(), randomDirections.begin(), randomDirections.end());
        if (candidates.empty()) {
            addUpdates(record, objectUpdates(g_, r.set, r.clear, facts), movementUpdates(g_, r, std::nullopt, facts));
        } else {
            for (int id : candidates) {
                const int layer = layerOfObject(g_, id);
                BitSet set = r.set;
                BitSet clear = r.clear;
                set.set(static_cast<size_t>(id));
                if (layer >= 0) clear |= g_.layerMasks[static_cast<size_t>(layer)];
                addUpdates(record, objectUpdates(g_, set, clear, facts),
                           movementUpdates(g_, r, layer >= 0 ? std::optional<int>(layer) : std::nullopt, facts));
            }
        }
        const RigidClaim claim = rigidClaim(g_, rule, r);
        record.push_back(static_cast<int>(claim.layers.size()));
        record.insert(record.end(), claim.layers.begin(), claim.layers.end());
        return shared(record);
    }

    const Game& g_;
    const std::vector<std::string> messages_;
    std::vector<int> data_;
    std::map<std::vector<int>, int> written_;
    bool layersExclusive_;
    int maxRows_ = 0;
    int maxSaved_ = 0;
};

std::string numbers(std::vector<int>::const_iterator begin, std::vector<int>::const_iterator end) {
    std::string out;
    for (auto it = begin; it != end; ++it) out += fmt::format("{}, ", *it);
    return out;
}

std::string hexWords(const std::vector<uint64_t>& words) {
    std::string out;
    for (size_t i = 0; i < words.size(); ++i) out += fmt::format("{}0x{:x}ull", i ? ", " : "", words[i]);
    return out;
}

}  // namespace

void emitRuleTableData(CodeWriter& out, const Game& game) {
    TableWriter table(game, ruleMessages(game));
    std::vector<int> ruleOffsets;
    std::vector<std::pair<size_t, std::string>> comments;  // where each rule's new records start, and its text
    for (const auto* groups : {&game.rules, &game.lateRules}) {
        for (const auto& group : *groups) {
            for (const auto& rule : group.rules) {
                comments.emplace_back(table.data().size(), fmt::format("line {}: {}", rule.line, ir::ruleText(game, rule)));
                ruleOffsets.push_back(table.addRule(rule));
            }
        }
    }
    out.line("// ---- the rules as a table (the compact form; templates/rule_table.h reads it)");
    out.line(fmt::format("constexpr int kTableMaxRows = {};        // rows of the longest rule", table.maxRows()));
    out.line(fmt::format("constexpr int kTableMaxSavedCells = {};  // cells after a first ellipsis, most in one rule",
                         table.maxSavedCells()));
    std::vector<int> layerStart;
    std::vector<int> layerObjects;
    for (const auto& layer : game.layerMasks) {
        layerStart.push_back(static_cast<int>(layerObjects.size()));
        for (int id : layer.bits()) layerObjects.push_back(id);
    }
    layerStart.push_back(static_cast<int>(layerObjects.size()));
    if (layerObjects.empty()) layerObjects.push_back(0);
    out.line("// Each collision layer's objects: kLayerObjects[kLayerObjectStart[L] .. kLayerObjectStart[L + 1]).");
    out.line("PSC_TABLE int kLayerObjectStart[] = {" + numbers(layerStart.begin(), layerStart.end()) + "};");
    out.line("PSC_TABLE int kLayerObjects[] = {" + numbers(layerObjects.begin(), layerObjects.end()) + "};");
    out.line("// The records each rule adds (those it shares with earlier rules are not repeated), after its text.");
    out.line("PSC_TABLE int kRuleData[] = {");
    const std::vector<int>& data = table.data();
    for (size_t i = 0; i < comments.size(); ++i) {
        const size_t begin = comments[i].first;
        const size_t end = i + 1 < comments.size() ? comments[i + 1].first : data.size();
        out.line("    // " + comments[i].second);
        out.line("    " + numbers(data.begin() + static_cast<std::ptrdiff_t>(begin), data.begin() + static_cast<std::ptrdiff_t>(end)));
    }
    if (data.empty()) out.line("    0");
    out.line("};");
    out.line("// Each rule's offset in kRuleData, early rules then late ones, group by group.");
    out.line("PSC_TABLE int kRuleIndex[] = {");
    for (size_t i = 0; i < ruleOffsets.size(); i += 16) {
        out.line("    " + numbers(ruleOffsets.begin() + static_cast<std::ptrdiff_t>(i),
                                  ruleOffsets.begin() + static_cast<std::ptrdiff_t>(std::min(i + 16, ruleOffsets.size()))));
    }
    if (ruleOffsets.empty()) out.line("    0");
    out.line("};");
    // Presence masks: each rule's needed boards (kRuleIndex order), and the
    // boards every rule of a group needs (the group is skipped while one is empty).
    const int words = presenceWords(game);
    out.line(fmt::format("constexpr int kTablePresenceWords = {};", words));
    out.line("// The presence bits of the boards each rule's every match needs, kTablePresenceWords a rule (kRuleIndex order).");
    out.line("PSC_TABLE u64 kRuleNeeds[] = {");
    std::vector<std::vector<uint64_t>> groupNeeds[2];
    for (const bool late : {false, true}) {
        for (const auto& group : late ? game.lateRules : game.rules) {
            for (const auto& rule : group.rules) out.line("    " + hexWords(neededPresence(game, rule, words)) + ",");
            groupNeeds[late ? 1 : 0].push_back(groupNeededPresence(game, group, words));
        }
    }
    if (ruleOffsets.empty()) out.line("    0");
    out.line("};");
    for (const bool late : {false, true}) {
        out.line(fmt::format("// The presence bits every rule of a{} group needs, kTablePresenceWords a group.", late ? " late" : "n early"));
        out.line(fmt::format("PSC_TABLE u64 {}[] = {{", late ? "kLateGroupNeeds" : "kEarlyGroupNeeds"));
        for (const auto& needs : groupNeeds[late ? 1 : 0]) out.line("    " + hexWords(needs) + ",");
        if (groupNeeds[late ? 1 : 0].empty()) out.line("    0");
        out.line("};");
    }
    int first = 0;
    for (const bool late : {false, true}) {
        const auto& groups = late ? game.lateRules : game.rules;
        const auto& loops = late ? game.lateLoopPoints : game.loopPoints;
        const std::string name = late ? "kLateGroups" : "kEarlyGroups";
        out.line(fmt::format("constexpr int {} = {};", late ? "kLateGroupCount" : "kEarlyGroupCount", groups.size()));
        if (!late) out.line("// Each group: first rule (kRuleIndex), rules, random, rigid group (-1: none), loop back to (-1: none).");
        out.line("PSC_TABLE int " + name + "[] = {");
        for (size_t i = 0; i < groups.size(); ++i) {
            const auto& group = groups[i];
            int rigid = -1;
            if (!late) {
                auto it = game.groupIndexToRigidGroupIndex.find(static_cast<int>(i));
                if (it != game.groupIndexToRigidGroupIndex.end()) rigid = it->second;
            }
            auto loop = loops.find(static_cast<int>(i));
            const int count = static_cast<int>(group.rules.size());
            out.line(fmt::format("    {}, {}, {}, {}, {},  // group {} (line {})", first, count, group.random ? 1 : 0, rigid,
                                 loop == loops.end() ? -1 : loop->second, i, group.groupNumber));
            first += count;
        }
        if (groups.empty()) out.line("    0");
        out.line("};");
    }
    out.line();
}

void emitRuleTableGroups(CodeWriter& out) {
    // Compiled in the turn's unit (PSC_DEFINES_TURN, templates/core.h), declared for all.
    for (const char* phase : {"Early", "Late"}) {
        out.line(fmt::format("PSC_DEVICE PSC_TURN void apply{}Rules(Env& e, Turn& t);", phase));
        out.raw("#if PSC_DEFINES_TURN\n");
        out.open(fmt::format("PSC_DEVICE PSC_TURN void apply{}Rules(Env& e, Turn& t)", phase));
        out.line("PSC_ON_STACK(e);");
        out.line("PSC_ON_STACK(t);");
        out.line(fmt::format("tableApplyGroups(e, t, k{0}Groups, k{0}GroupNeeds, k{0}GroupCount);", phase));
        out.close();
        out.raw("#endif\n");
    }
    out.line();
}

}  // namespace psc::codegen
