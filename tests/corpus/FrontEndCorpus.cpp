// psc-frontend-corpus: checks the front end against the reference's verdicts.
//
//   errors    every `kind: errors` case: psc reports an error iff the reference did
//   accept    every game of a trace case: psc builds it (the reference plays it)
//   compiled  every game in compiled/: psc's IR, in the oracle's format, equals the
//             reference compiler's output (error count, objects, layers, legend,
//             rules in order, loops, rigid groups, win conditions, levels, sounds)
//
// Prints a summary line per suite and the failures; `--min PERCENT` makes the
// exit status fail when a suite's pass rate is below it; `--json FILE` writes
// the counts and failures for docs/fidelity.md.
#include <fmt/format.h>

#include <chrono>
#include <fstream>
#include <map>
#include <set>

#include "Compiler.h"
#include "CorpusCases.h"
#include "ir/ReferenceDump.h"
#include "base/Sha1.h"

namespace {

using namespace psc;

struct SuiteResult {
    std::string name;
    int passed = 0;
    int total = 0;
    std::vector<std::pair<std::string, std::string>> failures;  // id, reason
    double percent() const { return total ? 100.0 * passed / total : 100.0; }
};

bool pscHasError(const CompileResult& r) {
    return r.diagnostics.errorCount() > 0 || r.status == CompileStatus::Aborted || r.status == CompileStatus::Invalid ||
           r.status == CompileStatus::ParseGaveUp;
}

SuiteResult checkErrors(const std::string& dir, const std::vector<corpus::IndexEntry>& index) {
    SuiteResult s{"errors"};
    for (const auto& e : index) {
        if (e.kind != "errors") continue;
        auto c = corpus::readJsonFile(dir + "/" + e.path);
        bool expected = c.at("expect_error").get<bool>() || c.contains("threw");
        CompileResult r = compileSource(c.at("game").get<std::string>());
        ++s.total;
        if (pscHasError(r) == expected) {
            ++s.passed;
        } else {
            s.failures.emplace_back(e.id, fmt::format("reference {} error(s), psc {} ({})", c.at("error_count").get<int>(),
                                                      r.diagnostics.errorCount(), statusName(r.status)));
        }
    }
    return s;
}

SuiteResult checkAccept(const std::string& dir, const std::vector<corpus::IndexEntry>& index) {
    SuiteResult s{"accept"};
    std::set<std::string> seen;
    for (const auto& e : index) {
        if (e.kind != "trace") continue;
        auto c = corpus::readJsonFile(dir + "/" + e.path);
        const std::string game = c.at("game").get<std::string>();
        if (!seen.insert(sha1Hex(game)).second) continue;
        CompileResult r = compileSource(game);
        ++s.total;
        if (r.playable()) ++s.passed;
        else s.failures.emplace_back(e.id, fmt::format("psc: {} ({} errors)", statusName(r.status), r.diagnostics.errorCount()));
    }
    return s;
}

SuiteResult checkCompiled(const std::string& dir, const std::vector<corpus::IndexEntry>& index) {
    SuiteResult s{"compiled"};
    std::map<std::string, std::string> pathOf;
    for (const auto& e : index) pathOf[e.id] = e.path;
    auto compiledIndex = corpus::readJsonFile(dir + "/compiled/INDEX.json");
    for (auto it = compiledIndex.begin(); it != compiledIndex.end(); ++it) {
        const std::string sha1 = it.key();
        const std::string caseId = it.value().at(0);
        auto c = corpus::readJsonFile(dir + "/" + pathOf.at(caseId));
        auto expected = corpus::readJsonFile(dir + "/compiled/" + sha1 + ".json");
        CompileResult r = compileSource(c.at("game").get<std::string>());
        ++s.total;
        if (!r.game) {
            s.failures.emplace_back(caseId, fmt::format("psc built no game: {}", statusName(r.status)));
            continue;
        }
        auto actual = nlohmann::json::parse(ir::referenceDump(*r.game, sha1).compact());
        expected.erase("notes");
        actual.erase("notes");
        std::string diff = corpus::firstDifference(actual, expected);
        if (diff.empty()) ++s.passed;
        else s.failures.emplace_back(caseId, sha1 + " " + diff.substr(0, 300));
    }
    return s;
}

}  // namespace

int main(int argc, char** argv) {
    std::string dir = "../shared/corpus";
    std::vector<std::string> suites;
    double minPercent = 0;
    std::string jsonOut;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a == "--corpus" && i + 1 < argc) dir = argv[++i];
        else if (a == "--min" && i + 1 < argc) minPercent = std::stod(argv[++i]);
        else if (a == "--json" && i + 1 < argc) jsonOut = argv[++i];
        else suites.push_back(a);
    }
    if (suites.empty()) suites = {"errors", "accept", "compiled"};
    auto index = corpus::readIndex(dir);
    bool ok = true;
    nlohmann::json report = nlohmann::json::object();
    for (const auto& name : suites) {
        auto start = std::chrono::steady_clock::now();
        SuiteResult s = name == "errors" ? checkErrors(dir, index) : name == "accept" ? checkAccept(dir, index)
                                                                                     : checkCompiled(dir, index);
        double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        for (const auto& [id, why] : s.failures) fmt::print("FAIL {} {}: {}\n", s.name, id, why);
        fmt::print("{}: {}/{} passed ({:.2f}%) in {:.1f} s\n", s.name, s.passed, s.total, s.percent(), seconds);
        if (s.percent() < minPercent) ok = false;
        nlohmann::json failures = nlohmann::json::array();
        for (const auto& [id, why] : s.failures) failures.push_back({{"id", id}, {"reason", why}});
        report[s.name] = {{"passed", s.passed}, {"total", s.total}, {"failures", failures}};
    }
    if (!jsonOut.empty()) std::ofstream(jsonOut) << report.dump(2) << "\n";
    return ok ? 0 : 1;
}
