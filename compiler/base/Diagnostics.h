// Errors and warnings with the reference compiler's bookkeeping.
//
// Whether a game "has errors" must agree with the reference exactly, so the
// counting follows its rules: an identical message on the same line is
// reported once; errors count; a warning without a line number also counts
// (the reference treats it as an error); more than 100 messages abort the
// compile.  Messages are psc's own words.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace psc {

enum class Severity { Error, Warning };

struct Diagnostic {
    Severity severity;
    std::optional<int> line;  // 1-based source line; none for whole-file problems
    int column = 0;           // 1-based, 0 when unknown
    std::string message;
    bool counted = false;     // counted towards the error count
};

// Thrown when the reference would abort the compile outright.
class CompileAborted : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

class Diagnostics {
public:
    static constexpr size_t kMaxMessages = 100;

    void error(std::optional<int> line, std::string message, int column = 0);
    void warning(std::optional<int> line, std::string message, int column = 0);
    // Reported even when identical to an earlier message (the reference's
    // "urgent" messages, logged after compilation proper).
    void urgentError(std::optional<int> line, std::string message);
    void urgentWarning(std::optional<int> line, std::string message);

    int errorCount() const { return errorCount_; }
    const std::vector<Diagnostic>& all() const { return messages_; }

private:
    void add(Severity severity, std::optional<int> line, std::string message, int column, bool urgent);

    std::vector<Diagnostic> messages_;
    int errorCount_ = 0;
};

}  // namespace psc
