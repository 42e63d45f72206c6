#include "Identifiers.h"

#include <fmt/format.h>

#include <algorithm>

namespace psc::codegen {

std::string sanitize(const std::string& name, const std::string& fallback) {
    std::string out;
    for (char c : name) {
        if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_') out += c;
    }
    return out.empty() ? fallback : out;
}

std::string ruleIdentifier(const ir::Game& game, const ir::Rule& rule, bool late) {
    std::vector<std::string> names;
    for (const auto& row : rule.rows) {
        for (const auto& cell : row) {
            cell.present.forEach([&](size_t id) {
                std::string n = sanitize(game.objects[id].name, fmt::format("obj{}", id));
                if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
            });
        }
    }
    std::string out = fmt::format("{}rule_L{}_{}", late ? "late_" : "", rule.line, sanitize(ir::directionName(rule.direction), "dir"));
    for (size_t i = 0; i < names.size() && i < 3; ++i) out += "_" + names[i];
    if (out.size() > 60) out.resize(60);
    return out;
}

std::string uniqueIdentifier(const std::string& base, std::set<std::string>& used) {
    std::string name = base;
    for (int n = 2; used.count(name); ++n) name = fmt::format("{}_{}", base, n);
    used.insert(name);
    return name;
}

}  // namespace psc::codegen
