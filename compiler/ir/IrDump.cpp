#include "ir/IrDump.h"

#include <fmt/format.h>

#include "ir/ReferenceDump.h"

namespace psc::ir {
namespace {

const char* const kWords[5] = {"up", "down", "left", "right", "action"};

std::string name(const Game& g, size_t id) {
    return id < g.objects.size() ? g.objects[id].name : "#" + std::to_string(id);
}

std::string fieldWords(uint32_t field) {
    std::string out;
    for (int k = 0; k < 5; ++k) {
        if ((field >> k) & 1u) out += std::string(out.empty() ? "" : "+") + kWords[k];
    }
    return out;
}

std::string names(const Game& g, const BitSet& mask, const char* sep) {
    std::string out;
    mask.forEach([&](size_t id) { out += (out.empty() ? "" : sep) + name(g, id); });
    return out;
}

int layerOf(const Game& g, size_t id) { return id < g.objects.size() && g.objects[id].layer ? *g.objects[id].layer : -1; }

std::string leftCell(const Game& g, const CellPattern& c) {
    if (c.ellipsis) return "...";
    std::vector<std::string> items;
    std::vector<bool> layerSaid(static_cast<size_t>(g.layerCount), false);
    c.present.forEach([&](size_t id) {
        int L = layerOf(g, id);
        std::string prefix;
        if (L >= 0) {
            if (c.movementsMissing.field(L) == 31u) prefix = "stationary ";
            else if (uint32_t f = c.movementsPresent.field(L)) prefix = fieldWords(f) + " ";
            layerSaid[static_cast<size_t>(L)] = true;
        }
        items.push_back(prefix + name(g, id));
    });
    for (const auto& any : c.anyOf) items.push_back("(" + names(g, any, "|") + ")");
    c.missing.forEach([&](size_t id) { items.push_back("no " + name(g, id)); });
    for (int L = 0; L < g.layerCount; ++L) {
        if (layerSaid[static_cast<size_t>(L)]) continue;
        if (c.movementsMissing.field(L) == 31u) items.push_back(fmt::format("stationary@{}", L));
        else if (uint32_t f = c.movementsPresent.field(L)) items.push_back(fmt::format("{}@{}", fieldWords(f), L));
    }
    std::string out;
    for (const auto& i : items) out += (out.empty() ? "" : " ") + i;
    return out;
}

std::string rightCell(const Game& g, const CellPattern& c) {
    if (c.ellipsis) return "...";
    if (!c.replacement) return "=";
    const Replacement& r = *c.replacement;
    std::vector<std::string> items;
    std::vector<bool> layerSaid(static_cast<size_t>(g.layerCount), false);
    r.set.forEach([&](size_t id) {
        int L = layerOf(g, id);
        std::string prefix;
        if (L >= 0) {
            if (uint32_t f = r.movementsSet.field(L)) prefix = fieldWords(f) + " ";
            else if (r.movementsClear.field(L) == 31u) prefix = "stationary ";
            layerSaid[static_cast<size_t>(L)] = true;
        }
        items.push_back(prefix + name(g, id));
    });
    r.clear.forEach([&](size_t id) {
        int L = layerOf(g, id);
        if (!r.set.test(id) && (L < 0 || !layerSaid[static_cast<size_t>(L)])) items.push_back("no " + name(g, id));
    });
    if (r.randomEntity.any()) items.push_back("random(" + names(g, r.randomEntity, "|") + ")");
    for (int L = 0; L < g.layerCount; ++L) {
        if (r.randomDirMask.test(static_cast<size_t>(5 * L))) items.push_back(fmt::format("randomdir@{}", L));
        if (layerSaid[static_cast<size_t>(L)]) continue;
        if (uint32_t f = r.movementsSet.field(L)) items.push_back(fmt::format("{}@{}", fieldWords(f), L));
        else if (r.movementsClear.field(L) || r.movementsLayerMask.field(L)) items.push_back(fmt::format("still@{}", L));
    }
    std::string out;
    for (const auto& i : items) out += (out.empty() ? "" : " ") + i;
    return out;
}

std::string rowText(const std::vector<std::string>& cells) {
    std::string out = "[ ";
    for (size_t i = 0; i < cells.size(); ++i) out += (i ? " | " : "") + cells[i];
    return out + " ]";
}

}  // namespace

std::string ruleText(const Game& g, const Rule& rule) {
    std::string out = directionName(rule.direction);
    if (rule.late) out = "late " + out;
    if (rule.rigid) out = "rigid " + out;
    if (rule.random) out = "random " + out;
    std::string lhs;
    std::string rhs;
    for (const auto& row : rule.rows) {
        std::vector<std::string> left;
        std::vector<std::string> right;
        for (const auto& c : row) {
            left.push_back(leftCell(g, c));
            right.push_back(rightCell(g, c));
        }
        lhs += " " + rowText(left);
        rhs += " " + rowText(right);
    }
    out += lhs + " ->" + (rule.hasReplacements ? rhs : "");
    for (const auto& c : rule.commands) out += " " + c.name + (c.name == "message" ? " \"" + c.message + "\"" : "");
    return out;
}

std::string dumpText(const Game& g, const std::string& sourceName) {
    std::string out = fmt::format("; psc IR of {} ({})\n", sourceName, g.title.empty() ? "untitled" : g.title);
    out += fmt::format("; {} objects, {} collision layers, {} + {} rule groups, {} levels\n", g.objectCount,
                       g.layerCount, g.rules.size(), g.lateRules.size(), g.levels.size());
    out += "\nprelude\n";
    for (const auto& [k, v] : g.metadata) {
        out += "  " + k + (v.size ? fmt::format(" {}x{}", v.size->first, v.size->second) : " " + v.text) + "\n";
    }
    out += "\nobjects (id name @layer)\n";
    for (const auto& o : g.objects) {
        if (o.ghost) out += fmt::format("  {:>3} {} (ghost of id {})\n", o.id, o.name, o.liveId.value_or(-1));
        else out += fmt::format("  {:>3} {} @{}\n", o.id, o.name, o.layer.value_or(-1));
    }
    out += "\ncollision layers\n";
    for (size_t L = 0; L < g.layerMasks.size(); ++L) out += fmt::format("  {:>3} {}\n", L, names(g, g.layerMasks[L], " "));
    out += fmt::format("\nplayer: {}{}\n", names(g, g.playerMask, g.playerIsAggregate ? " and " : " or "),
                       g.playerIsAggregate ? " (all together)" : "");
    if (g.background) out += fmt::format("background: {} @{}\n", name(g, static_cast<size_t>(g.background->id)), g.background->layer);

    auto groups = [&](const char* title, const std::vector<RuleGroup>& list, const std::map<int, int>& loops) {
        out += fmt::format("\n{}\n", title);
        for (size_t i = 0; i < list.size(); ++i) {
            const RuleGroup& group = list[i];
            std::string extra;
            if (group.random) extra += " random";
            if (auto it = g.groupIndexToRigidGroupIndex.find(static_cast<int>(i));
                it != g.groupIndexToRigidGroupIndex.end() && &list == &g.rules) {
                extra += fmt::format(" rigid#{}", it->second);
            }
            if (auto it = loops.find(static_cast<int>(i)); it != loops.end()) extra += fmt::format(" loops back to group {}", it->second);
            out += fmt::format("  group {} (line {}){}\n", i, group.groupNumber, extra);
            for (const auto& r : group.rules) out += fmt::format("    L{:<5} {}\n", r.line, ruleText(g, r));
        }
    };
    groups("rules", g.rules, g.loopPoints);
    groups("late rules", g.lateRules, g.lateLoopPoints);

    out += "\nwin conditions\n";
    for (const auto& w : g.winConditions) {
        const char* q = w.quantifier < 0 ? "no" : w.quantifier > 0 ? "all" : "some";
        out += fmt::format("  L{:<5} {} {}{}\n", w.line, q, names(g, w.objects, w.aggregate1 ? "&" : "|"),
                           w.onEverything ? "" : " on " + names(g, w.on, w.aggregate2 ? "&" : "|"));
    }
    out += "\nlevels\n";
    int playable = 0;
    for (size_t i = 0; i < g.levels.size(); ++i) {
        const Level& l = g.levels[i];
        if (l.isMessage) out += fmt::format("  entry {:>3}: message \"{}\"\n", i, l.message);
        else out += fmt::format("  entry {:>3}: level {} ({}x{}, line {})\n", i, playable++, l.width, l.height, l.line);
    }
    return out;
}

nlohmann::ordered_json dumpJson(const Game& g, const std::string& sourceSha1) {
    nlohmann::ordered_json out = nlohmann::ordered_json::parse(referenceDump(g, sourceSha1).compact());
    auto& entries = out["levels"]["entries"];
    for (size_t i = 0; i < g.levels.size(); ++i) {
        const Level& l = g.levels[i];
        if (l.isMessage) continue;
        nlohmann::ordered_json rows = nlohmann::ordered_json::array();
        for (int y = 0; y < l.height; ++y) {
            nlohmann::ordered_json row = nlohmann::ordered_json::array();
            for (int x = 0; x < l.width; ++x) {
                nlohmann::ordered_json cell = nlohmann::ordered_json::array();
                l.cells[static_cast<size_t>(x * l.height + y)].forEach([&](size_t id) { cell.push_back(name(g, id)); });
                row.push_back(cell);
            }
            rows.push_back(row);
        }
        entries[i]["rows"] = rows;
    }
    return out;
}

}  // namespace psc::ir
