#include "ast/AstDump.h"

#include <fmt/format.h>

#include "base/JsString.h"

namespace psc::ast {
namespace {

std::string kindName(LegendDecl::Kind k) {
    switch (k) {
        case LegendDecl::Kind::Synonym: return "synonym";
        case LegendDecl::Kind::Aggregate: return "aggregate";
        case LegendDecl::Kind::Property: return "property";
    }
    return "?";
}

std::string soundKind(SoundWord::Kind k) {
    switch (k) {
        case SoundWord::Kind::Event: return "event";
        case SoundWord::Kind::Name: return "name";
        case SoundWord::Kind::Verb: return "verb";
        case SoundWord::Kind::Direction: return "direction";
        case SoundWord::Kind::Seed: return "seed";
    }
    return "?";
}

std::string join(const std::vector<std::string>& items, const std::string& sep) {
    std::string out;
    for (size_t i = 0; i < items.size(); ++i) out += (i ? sep : "") + items[i];
    return out;
}

}  // namespace

std::string dumpText(const Game& g) {
    std::string out;
    out += "prelude\n";
    for (const auto& m : g.metadata) out += fmt::format("  L{:<5} {} = {}\n", m.line, m.key, m.value);
    out += "objects\n";
    for (const auto& o : g.objects) {
        out += fmt::format("  L{:<5} {}  colours: {}{}\n", o.line, o.name, join(o.colors, " "),
                           o.spriteRows.empty() ? "" : "  sprite: " + join(o.spriteRows, "/"));
    }
    out += "legend\n";
    auto legend = [&](const std::vector<LegendDecl>& list) {
        for (const auto& e : list) {
            const char* op = e.kind == LegendDecl::Kind::Aggregate ? " and " : " or ";
            out += fmt::format("  L{:<5} {} = {}   ({})\n", e.line, e.name, join(e.members, op), kindName(e.kind));
        }
    };
    legend(g.synonyms);
    legend(g.aggregates);
    legend(g.properties);
    out += "sounds\n";
    for (const auto& s : g.sounds) {
        std::vector<std::string> words;
        for (const auto& w : s.words) words.push_back(w.text);
        out += fmt::format("  L{:<5} {}\n", s.line, join(words, " "));
    }
    out += "collisionlayers\n";
    for (size_t i = 0; i < g.collisionLayers.size(); ++i) {
        out += fmt::format("  {:<6} {}\n", i, join(g.collisionLayers[i], ", "));
    }
    out += "rules\n";
    for (const auto& r : g.rules) out += fmt::format("  L{:<5} {}\n", r.line, js::toUtf8(js::trim(r.text)));
    out += "winconditions\n";
    for (const auto& w : g.winConditions) out += fmt::format("  L{:<5} {}\n", w.line, join(w.words, " "));
    out += "levels\n";
    for (const auto& l : g.levels) {
        if (l.isMessage) {
            out += fmt::format("  L{:<5} message {}\n", l.line, l.message);
        } else if (!l.rows.empty()) {
            out += fmt::format("  L{:<5} level {}x{}\n", l.line, l.rows.front().size(), l.rows.size());
            for (const auto& row : l.rows) out += "           " + js::toUtf8(row) + "\n";
        }
    }
    return out;
}

nlohmann::ordered_json dumpJson(const Game& g) {
    using J = nlohmann::ordered_json;
    J out = J::object();
    J prelude = J::array();
    for (const auto& m : g.metadata) prelude.push_back({{"key", m.key}, {"value", m.value}, {"line", m.line}});
    out["prelude"] = prelude;
    J objects = J::array();
    for (const auto& o : g.objects) {
        objects.push_back({{"name", o.name}, {"line", o.line}, {"colors", o.colors}, {"sprite", o.spriteRows}});
    }
    out["objects"] = objects;
    J legend = J::array();
    for (const auto* list : {&g.synonyms, &g.aggregates, &g.properties}) {
        for (const auto& e : *list) {
            legend.push_back({{"name", e.name}, {"kind", kindName(e.kind)}, {"members", e.members}, {"line", e.line}});
        }
    }
    out["legend"] = legend;
    J sounds = J::array();
    for (const auto& s : g.sounds) {
        J words = J::array();
        for (const auto& w : s.words) words.push_back({{"kind", soundKind(w.kind)}, {"text", w.text}});
        sounds.push_back({{"words", words}, {"line", s.line}});
    }
    out["sounds"] = sounds;
    out["collision_layers"] = g.collisionLayers;
    J rules = J::array();
    for (const auto& r : g.rules) rules.push_back({{"text", js::toUtf8(js::trim(r.text))}, {"line", r.line}});
    out["rules"] = rules;
    J wins = J::array();
    for (const auto& w : g.winConditions) wins.push_back({{"words", w.words}, {"line", w.line}});
    out["win_conditions"] = wins;
    J levels = J::array();
    for (const auto& l : g.levels) {
        if (l.isMessage) {
            levels.push_back({{"message", l.message}, {"line", l.line}});
        } else if (!l.rows.empty()) {
            J rows = J::array();
            for (const auto& row : l.rows) rows.push_back(js::toUtf8(row));
            levels.push_back({{"rows", rows}, {"line", l.line}});
        }
    }
    out["levels"] = levels;
    return out;
}

}  // namespace psc::ast
