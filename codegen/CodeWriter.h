// A text buffer for generated code that keeps track of indentation.
#pragma once

#include <string>

namespace psc::codegen {

class CodeWriter {
public:
    CodeWriter() = default;
    // Starts at another writer's indentation, for text to be placed there later.
    explicit CodeWriter(int indent) : indent_(indent) {}
    int indent() const { return indent_; }
    // Appends one line at the current indentation ("" for an empty line).
    void line(const std::string& text = "") {
        if (!text.empty()) out_.append(static_cast<size_t>(indent_) * 4, ' ');
        out_ += text;
        out_ += '\n';
    }
    // "text {" and indent; close() dedents and writes "}" plus an optional suffix.
    void open(const std::string& text) {
        line(text.empty() ? "{" : text + " {");
        ++indent_;
    }
    void close(const std::string& suffix = "") {
        --indent_;
        line("}" + suffix);
    }
    void raw(const std::string& text) { out_ += text; }
    const std::string& text() const { return out_; }

private:
    std::string out_;
    int indent_ = 0;
};

}  // namespace psc::codegen
