#include "base/Diagnostics.h"

namespace psc {

void Diagnostics::error(std::optional<int> line, std::string message, int column) {
    add(Severity::Error, line, std::move(message), column, false);
}

void Diagnostics::warning(std::optional<int> line, std::string message, int column) {
    add(Severity::Warning, line, std::move(message), column, false);
}

void Diagnostics::urgentError(std::optional<int> line, std::string message) {
    add(Severity::Error, line, std::move(message), 0, true);
}

void Diagnostics::urgentWarning(std::optional<int> line, std::string message) {
    add(Severity::Warning, line, std::move(message), 0, true);
}

void Diagnostics::add(Severity severity, std::optional<int> line, std::string message, int column, bool urgent) {
    if (!urgent) {
        for (const Diagnostic& d : messages_) {
            if (d.severity == severity && d.line == line && d.message == message) return;
        }
    }
    bool counted = severity == Severity::Error || !line.has_value();
    if (counted) ++errorCount_;
    messages_.push_back(Diagnostic{severity, line, column, std::move(message), counted});
    if (messages_.size() > kMaxMessages) throw CompileAborted("too many errors and warnings; compilation aborted");
}

}  // namespace psc
