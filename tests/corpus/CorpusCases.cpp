#include "CorpusCases.h"

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace psc::corpus {

nlohmann::json readJsonFile(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path);
    std::stringstream ss;
    ss << in.rdbuf();
    return nlohmann::json::parse(ss.str());
}

std::vector<IndexEntry> readIndex(const std::string& corpusDir) {
    std::vector<IndexEntry> out;
    for (const auto& e : readJsonFile(corpusDir + "/INDEX.json")) {
        out.push_back({e.at("id"), e.at("suite"), e.at("kind"), e.at("path")});
    }
    return out;
}

std::string firstDifference(const nlohmann::json& a, const nlohmann::json& b, const std::string& where) {
    if (a.type() != b.type()) return where.empty() ? "/" : where;
    if (a.is_object()) {
        for (auto it = a.begin(); it != a.end(); ++it) {
            if (!b.contains(it.key())) return where + "/" + it.key() + " (only in psc)";
            std::string d = firstDifference(it.value(), b.at(it.key()), where + "/" + it.key());
            if (!d.empty()) return d;
        }
        for (auto it = b.begin(); it != b.end(); ++it) {
            if (!a.contains(it.key())) return where + "/" + it.key() + " (only in the reference)";
        }
        return "";
    }
    if (a.is_array()) {
        if (a.size() != b.size()) {
            return where + " (length " + std::to_string(a.size()) + " vs " + std::to_string(b.size()) + ")";
        }
        for (size_t i = 0; i < a.size(); ++i) {
            std::string d = firstDifference(a[i], b[i], where + "/" + std::to_string(i));
            if (!d.empty()) return d;
        }
        return "";
    }
    return a == b ? "" : where + " (" + a.dump() + " vs " + b.dump() + ")";
}

}  // namespace psc::corpus
