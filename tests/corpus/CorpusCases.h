// Reading the golden-trace corpus (../shared/corpus, FORMAT.md): its index
// and case files.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace psc::corpus {

struct IndexEntry {
    std::string id;
    std::string suite;  // testsuite, errors, scraped
    std::string kind;   // trace, errors
    std::string path;   // relative to the corpus root
};

std::vector<IndexEntry> readIndex(const std::string& corpusDir);
nlohmann::json readJsonFile(const std::string& path);

// The first differing place between two JSON values ("" when equal).
std::string firstDifference(const nlohmann::json& a, const nlohmann::json& b, const std::string& where = "");

}  // namespace psc::corpus
