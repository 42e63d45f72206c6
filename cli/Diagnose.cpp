#include "Diagnose.h"

#include <fmt/format.h>

namespace psc::cli {
namespace {

// Messages may quote source text; keep them on one line and of sane length.
std::string printable(const std::string& message) {
    constexpr size_t kMaxLength = 240;
    std::string out;
    for (char c : message) out += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
    if (out.size() > kMaxLength) {
        size_t cut = kMaxLength;
        while (cut > 0 && (static_cast<unsigned char>(out[cut]) & 0xC0) == 0x80) --cut;
        out = out.substr(0, cut) + "...";
    }
    return out;
}

}  // namespace

void printDiagnostics(std::FILE* out, const std::string& path, const CompileResult& result) {
    for (const Diagnostic& d : result.diagnostics.all()) {
        const char* kind = d.severity == Severity::Error ? "error" : "warning";
        if (d.line) {
            fmt::print(out, "{}:{}:{}: {}: {}\n", path, *d.line, d.column > 0 ? d.column : 1, kind, printable(d.message));
        } else {
            fmt::print(out, "{}: {}: {}\n", path, kind, printable(d.message));
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
