#include "parse/RuleReader.h"

#include <algorithm>
#include <unordered_set>

#include "PuzzleScriptLexer.h"
#include "PuzzleScriptParser.h"
#include "antlr4-runtime.h"
#include "parse/Scanner.h"
#include "base/JsString.h"

namespace psc::parse {
namespace {

using js::toUpperAscii;

const std::unordered_set<std::string> kRelativeDirections = {"^", "v", "<", ">", "perpendicular", "parallel"};
const std::unordered_set<std::string> kModifiers = {">", "<", "^", "v", "up", "down", "left", "right", "moving",
                                                    "stationary", "no", "randomdir", "random", "horizontal",
                                                    "vertical", "orthogonal", "perpendicular", "parallel", "action"};

std::vector<std::string> expandPrefixDirection(const std::string& word) {
    if (word == "horizontal" || word == "horizontal_par" || word == "horizontal_perp") return {"left", "right"};
    if (word == "vertical" || word == "vertical_par" || word == "vertical_perp") return {"up", "down"};
    if (word == "moving") return {"up", "down", "left", "right", "action"};
    if (word == "orthogonal") return {"up", "down", "left", "right"};
    return {};
}

// The reference pads brackets, bars and arrows with spaces and splits a
// leading '+' from what follows before reading the tokens.
js::U16 padRuleText(const js::U16& text) {
    js::U16 out;
    for (char16_t c : text) {
        if (c == u'[' || c == u']' || c == u'|') {
            out += u' ';
            out += c;
            out += u' ';
        } else {
            out += c;
        }
    }
    js::U16 arrows;
    for (size_t i = 0; i < out.size(); ++i) {
        if (out[i] == u'-' && i + 1 < out.size() && out[i + 1] == u'>') {
            arrows += u" -> ";
            ++i;
        } else {
            arrows += out[i];
        }
    }
    js::U16 trimmed = js::trim(arrows);
    if (!trimmed.empty() && trimmed[0] == u'+') trimmed.insert(1, u" ");
    return trimmed;
}

class ThrowingErrorListener : public antlr4::BaseErrorListener {
public:
    void syntaxError(antlr4::Recognizer*, antlr4::Token*, size_t, size_t column, const std::string& msg,
                     std::exception_ptr) override {
        throw std::runtime_error("rule grammar: column " + std::to_string(column + 1) + ": " + msg);
    }
};

struct RuleTokens {
    std::vector<std::string> prefix;
    std::vector<std::string> body;
};

RuleTokens tokenize(const js::U16& text) {
    antlr4::ANTLRInputStream input(js::toUtf8(padRuleText(text)));
    grammar::PuzzleScriptLexer lexer(&input);
    ThrowingErrorListener listener;
    lexer.removeErrorListeners();
    lexer.addErrorListener(&listener);
    antlr4::CommonTokenStream tokens(&lexer);
    grammar::PuzzleScriptParser parser(&tokens);
    parser.removeErrorListeners();
    parser.addErrorListener(&listener);
    grammar::PuzzleScriptParser::RuleLineContext* line = parser.ruleLine();

    RuleTokens out;
    for (auto* t : line->rulePrefix()->prefixToken()) out.prefix.push_back(t->getText());
    auto* body = line->ruleBody();
    if (body->LBRACKET()) {
        out.body.push_back("[");
        for (auto* t : body->bodyToken()) out.body.push_back(t->getText());
    }
    return out;
}

bool cellRowHasRelativeDirection(const ast::RuleRow& row) {
    for (const auto& cell : row) {
        for (const auto& item : cell) {
            if (kRelativeDirections.count(item.modifier)) return true;
        }
    }
    return false;
}

bool isDirectional(const ast::RuleSyntax& rule) {
    for (const auto& row : rule.lhs) {
        if (row.size() > 1 || cellRowHasRelativeDirection(row)) return true;
    }
    for (const auto& row : rule.rhs) {
        if (cellRowHasRelativeDirection(row)) return true;
    }
    return false;
}

// Reads the tokens with the reference's two states: the prefix, then the cell rows.
class Reader {
public:
    Reader(const ast::RuleLineSource& source, const std::vector<ast::RuleSyntax>& previous,
           const RuleReaderContext& context, Diagnostics& diag)
        : source_(source), previous_(previous), context_(context), diag_(diag) {
        rule_.line = source.line;
        rule_.groupNumber = source.line;
    }

    std::optional<ast::RuleSyntax> read(bool* invalid);

private:
    bool readPrefixToken(size_t index, const std::string& token);
    bool readBodyToken(size_t index, const std::string& token);
    void addName(const std::string& token);
    void addCommand(size_t index, const std::string& token);

    void error(const std::string& m) { diag_.error(source_.line, m); }
    void warning(const std::string& m) { diag_.warning(source_.line, m); }

    const ast::RuleLineSource& source_;
    const std::vector<ast::RuleSyntax>& previous_;
    const RuleReaderContext& context_;
    Diagnostics& diag_;

    ast::RuleSyntax rule_;
    std::vector<std::string> tokens_;
    bool hasPlus_ = false;
    bool rhs_ = false;
    bool inCellRow_ = false;
    int bracketBalance_ = 0;
    std::vector<std::string> cell_;  // flat (modifier, name) pairs; odd length = a pending modifier
    ast::RuleRow row_;
    bool stop_ = false;
};

std::optional<ast::RuleSyntax> Reader::read(bool* invalid) {
    if (source_.original.find(u'(') != js::U16::npos && source_.text.find(u"->") == js::U16::npos) {
        error("a rule cannot contain a comment: '(' starts a comment, and the text before it has no '->'");
        return std::nullopt;
    }
    RuleTokens split = tokenize(source_.text);
    tokens_ = split.prefix;
    tokens_.insert(tokens_.end(), split.body.begin(), split.body.end());

    if (tokens_.empty()) error("empty rule line");
    if (tokens_.size() == 1 && tokens_[0] == "startloop") {
        rule_.kind = ast::RuleSyntax::Kind::StartLoop;
        return rule_;
    }
    if (tokens_.size() == 1 && tokens_[0] == "endloop") {
        rule_.kind = ast::RuleSyntax::Kind::EndLoop;
        return rule_;
    }
    if (std::find(tokens_.begin(), tokens_.end(), "->") == tokens_.end()) error("a rule needs an arrow '->'");

    for (size_t i = 0; i < split.prefix.size(); ++i) readPrefixToken(i, split.prefix[i]);
    if (!split.body.empty() && rule_.directions.empty()) rule_.directions = expandPrefixDirection("orthogonal");
    for (size_t i = split.prefix.size(); i < tokens_.size() && !stop_; ++i) {
        if (!readBodyToken(i, tokens_[i])) return std::nullopt;
    }

    if (rule_.late && rule_.rigid) error("late rules cannot be rigid (late rules have no movements to resolve)");
    if (rule_.lhs.size() != rule_.rhs.size()) {
        if (!(!rule_.commands.empty() && rule_.rhs.empty())) {
            warning("the left-hand side and the right-hand side need the same number of cell rows; rule ignored");
            return std::nullopt;
        }
    } else {
        for (size_t i = 0; i < rule_.lhs.size(); ++i) {
            if (rule_.lhs[i].size() != rule_.rhs[i].size()) {
                error("each cell row on the left needs a row of the same length on the right");
                *invalid = true;
            }
            if (rule_.lhs[i].empty()) diag_.error(std::nullopt, "a rule has an empty cell row on the left-hand side");
        }
    }
    if (rule_.lhs.empty()) error("this rule matches nothing: it has no cell rows");

    if (!isDirectional(rule_) && rule_.directions.size() > 1) rule_.directions.resize(1);
    return rule_;
}

bool Reader::readPrefixToken(size_t index, const std::string& token) {
    if (token == "+") {
        hasPlus_ = true;
        if (rule_.groupNumber == rule_.line) {
            if (previous_.empty()) {
                error("'+' joins the group of the previous rule, but there is no previous rule");
                hasPlus_ = false;
            }
            if (index != 0) error("'+' must be the first symbol on the line");
            if (hasPlus_) rule_.groupNumber = previous_.back().groupNumber;
        } else {
            error("a rule has two '+' signs");
        }
    } else if (kRelativeDirections.count(token)) {
        error("relative directions (^ v < >) cannot say which directions a rule applies in; use up, down, left, "
              "right, horizontal or vertical");
    } else if (auto dirs = expandPrefixDirection(token); !dirs.empty()) {
        rule_.directions.insert(rule_.directions.end(), dirs.begin(), dirs.end());
    } else if (token == "late") {
        rule_.late = true;
    } else if (token == "rigid") {
        rule_.rigid = true;
    } else if (token == "random") {
        rule_.random = true;
        if (hasPlus_) error("only the first rule of a group can be marked random ('+' and 'random' on one line)");
    } else if (token == "up" || token == "down" || token == "left" || token == "right") {
        rule_.directions.push_back(token);
    } else {
        error("before the first '[' a rule may only have directions, LATE, RIGID, RANDOM or '+', not \"" +
              toUpperAscii(token) + "\"");
    }
    return true;
}

bool Reader::readBodyToken(size_t index, const std::string& token) {
    if (token == "[") {
        ++bracketBalance_;
        if (bracketBalance_ > 1) warning("'[' opened again before the previous '[' was closed");
        if (!cell_.empty()) error("malformed cell: '[' before the previous cell was closed");
        inCellRow_ = true;
        cell_.clear();
    } else if (kModifiers.count(token)) {
        if (cell_.size() % 2 == 1) {
            error("an object can have only one direction or action at a time");
        } else if (!inCellRow_) {
            warning("directions belong at the start of a rule or inside cells");
        } else if (rule_.late && token != "no" && token != "random" && token != "randomdir") {
            error("late rules cannot mention movements");
        } else {
            cell_.push_back(token);
        }
    } else if (token == "|") {
        if (!inCellRow_) {
            warning("'|' belongs inside a cell row");
        } else if (cell_.size() % 2 == 1) {
            error("a movement in a rule must apply to an object");
        } else {
            ast::RuleCell cell;
            for (size_t k = 0; k + 1 < cell_.size(); k += 2) cell.push_back({cell_[k], cell_[k + 1]});
            row_.push_back(std::move(cell));
            cell_.clear();
        }
    } else if (token == "]") {
        --bracketBalance_;
        if (bracketBalance_ < 0) {
            warning("']' without a matching '['; rule ignored");
            return false;
        }
        if (cell_.size() % 2 == 1) {
            if (cell_[0] == "...") error("a rule cannot end with an ellipsis");
            else error("a movement in a rule must apply to an object");
        } else {
            ast::RuleCell cell;
            for (size_t k = 0; k + 1 < cell_.size(); k += 2) cell.push_back({cell_[k], cell_[k + 1]});
            row_.push_back(std::move(cell));
            cell_.clear();
        }
        (rhs_ ? rule_.rhs : rule_.lhs).push_back(std::move(row_));
        row_.clear();
        inCellRow_ = false;
    } else if (token == "->") {
        if (rule_.groupNumber != rule_.line && previous_.back().late != rule_.late) {
            warning("this group mixes late and normal rules");
        }
        if (inCellRow_) {
            warning("'->' inside square brackets is ignored");
        } else if (rhs_) {
            error("a rule can have only one '->'");
            return false;
        } else {
            rhs_ = true;
        }
    } else if (context_.names.count(token)) {
        addName(token);
    } else if (token == "...") {
        if (!inCellRow_) {
            warning("an ellipsis belongs inside a cell row");
        } else {
            cell_.push_back(token);
            cell_.push_back(token);
        }
    } else if (isCommandWord(token)) {
        addCommand(index, token);
    } else {
        error("malformed cell: did not expect \"" + token + "\" here");
    }
    return true;
}

void Reader::addName(const std::string& token) {
    if (!inCellRow_) {
        warning("object " + toUpperAscii(token) + " outside square brackets is ignored");
        return;
    }
    for (size_t j = 0; j + 1 < cell_.size(); j += 2) {
        if (cell_[j + 1] != token) continue;
        const std::string& existing = cell_[j];
        std::string incoming = cell_.size() % 2 == 1 ? cell_.back() : "";
        if (existing == "no" && incoming == "no") {
            warning("NO " + toUpperAscii(token) + " appears twice in one cell");
        } else {
            error("an object can appear only once in a cell (" + toUpperAscii(token) + " appears again)");
            if (context_.isProperty(token)) {
                diag_.warning(std::nullopt, "(" + toUpperAscii(token) + " is a property: to test it twice, define "
                              "a second property with the same members under another name)");
            }
        }
    }
    if (cell_.size() % 2 == 0) cell_.push_back("");
    cell_.push_back(token);
}

void Reader::addCommand(size_t index, const std::string& token) {
    if (!rhs_) {
        error("commands belong at the end of a rule, after the right-hand side");
    } else if (inCellRow_ || std::find(tokens_.begin() + static_cast<long>(index), tokens_.end(), "]") != tokens_.end()) {
        warning("commands belong at the end of a rule, after the right-hand side");
    }
    if (token == "message") {
        // The text is everything after this token in the line as written.
        js::U16 lower = js::toLower(source_.original);
        long at = 0;
        for (size_t i = 0; i <= index; ++i) {
            js::U16 t = js::fromUtf8(tokens_[i]);
            size_t found = lower.find(t, static_cast<size_t>(std::max<long>(at, 0)));
            at = (found == js::U16::npos ? -1 : static_cast<long>(found)) + static_cast<long>(t.size());
        }
        js::U16 rest = at < 0 ? source_.original : source_.original.substr(std::min<size_t>(at, source_.original.size()));
        std::string text = js::toUtf8(js::trim(rest));
        if (text.empty()) text = " ";
        rule_.commands.push_back({token, text});
        stop_ = true;
        return;
    }
    if (token.rfind("sfx", 0) == 0) {
        bool defined = std::any_of(context_.sounds.begin(), context_.sounds.end(), [&](const ast::SoundDecl& s) {
            return !s.words.empty() && s.words[0].text == token;
        });
        if (!defined) warning("sound effect " + token + " is not defined in SOUNDS");
    }
    rule_.commands.push_back({token, ""});
}

}  // namespace

std::optional<ast::RuleSyntax> readRuleLine(const ast::RuleLineSource& source,
                                            const std::vector<ast::RuleSyntax>& previous,
                                            const RuleReaderContext& context, Diagnostics& diagnostics,
                                            bool* invalid) {
    return Reader(source, previous, context, diagnostics).read(invalid);
}

std::vector<std::string> ruleTokens(const std::u16string& text) {
    RuleTokens t = tokenize(text);
    t.prefix.insert(t.prefix.end(), t.body.begin(), t.body.end());
    return t.prefix;
}

}  // namespace psc::parse
