#include "Diagnose.h"

#include <fmt/format.h>

namespace psc::cli {

void printDiagnostics(std::FILE* out, const std::string& path, const CompileResult& result) {
    for (const Diagnostic& d : result.diagnostics.all()) {
        const char* kind = d.severity == Severity::Error ? "error" : "warning";
        if (d.line) {
            fmt::print(out, "{}:{}:{}: {}: {}\n", path, *d.line, d.column > 0 ? d.column : 1, kind, d.message);
        } else {
            fmt::print(out, "{}: {}: {}\n", path, kind, d.message);
        }
    }
    if (result.status == CompileStatus::Aborted) fmt::print(out, "{}: error: {}\n", path, result.abortReason);
}

std::string verdict(const CompileResult& result) {
    switch (result.status) {
        case CompileStatus::Ok: return "ok";
        case CompileStatus::Playable:
            return fmt::format("{} error(s); the reference engine still plays this game (build it with --keep-going)",
                               result.diagnostics.errorCount());
        case CompileStatus::Refused:
            return fmt::format("{} errors; the reference engine refuses to start the game", result.diagnostics.errorCount());
        case CompileStatus::Invalid: return "a fatal error; the game cannot be built";
        case CompileStatus::ParseGaveUp: return "too many errors; parsing stopped";
        case CompileStatus::Aborted: return "compilation aborted";
    }
    return "?";
}

}  // namespace psc::cli
