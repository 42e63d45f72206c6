// A cursor over one source line, and the token shapes the scanner looks for.
//
// The reference tokenizer reads each line with a cursor and anchored regular
// expressions; the matchers below are those shapes written out by hand, with
// the same greediness, alternation order and Unicode classes.  Each returns
// the number of UTF-16 code units matched at `pos`, or kNoMatch.
#pragma once

#include <string>
#include <string_view>

#include "base/JsString.h"

namespace psc::parse {

using js::U16;
inline constexpr size_t kNoMatch = static_cast<size_t>(-1);

class LineCursor {
public:
    explicit LineCursor(U16 text) : text_(std::move(text)) {}

    const U16& text() const { return text_; }
    void replaceText(U16 text) { text_ = std::move(text); }
    size_t pos() const { return pos_; }
    std::u16string_view rest() const { return std::u16string_view(text_).substr(std::min(pos_, text_.size())); }

    bool sol() const { return pos_ == 0; }
    bool eol() const { return pos_ >= text_.size(); }
    // The next code unit, or -1 at the end of the line.
    int peek() const { return eol() ? -1 : text_[pos_]; }
    void next() {
        if (!eol()) ++pos_;
    }
    void advance(size_t n) { pos_ = std::min(pos_ + n, text_.size()); }
    void skipToEnd() { pos_ = text_.size(); }
    void eatSpace();
    // Consumes the match if there is one; returns its length or kNoMatch.
    size_t consume(size_t length) {
        if (length != kNoMatch) advance(length);
        return length;
    }

private:
    U16 text_;
    size_t pos_ = 0;
};

// [\p{L}\p{N}_]+[\p{Z}\s]*
size_t matchName(std::u16string_view s);
// [\p{Z}\s]*[\p{L}\p{N}_]+[\p{Z}\s]*
size_t matchSingleWord(std::u16string_view s);
// [^\p{Z}\s()]+[\p{Z}\s]*
size_t matchWordUntilSpaceOrParen(std::u16string_view s);
// [^=\p{Z}\s(]*(\p{Z}\s)*  (the legend's left-hand name; may be empty)
size_t matchLegendKey(std::u16string_view s);
// [^(]+
size_t matchUntilParen(std::u16string_view s);
// [\p{Z}\s]*
size_t matchWhitespace(std::u16string_view s);
// [ ,]*
size_t matchLayerSeparators(std::u16string_view s);
// =+
size_t matchEqualsRun(std::u16string_view s);
// ^[\p{Z}\s=]*$
bool isEqualsLine(std::u16string_view s);
// [\p{Z}\s]*->[\p{Z}\s]*
size_t matchRuleArrow(std::u16string_view s);
// [^\[|\]\p{Z}\s]*
size_t matchRulePart(std::u16string_view s);
// \d+\b
size_t matchSoundSeed(std::u16string_view s);
// [\p{Z}\s]*message\b[\p{Z}\s]*   and the same without \b
size_t matchMessageKeyword(std::u16string_view s, bool requireBoundary);

// Keyword alternations; `word` receives the alternative that matched.
// (objects|collisionlayers|legend|sounds|rules|winconditions|levels)(?![\p{L}\p{N}_])[\p{Z}\s]*
size_t matchSectionName(std::u16string_view s, std::string* word);
// (move|action|create|destroy|cantmove)\b[\p{Z}\s]*
size_t matchSoundVerb(std::u16string_view s, std::string* word);
// (undo|restart|...|sfx10)\b[\p{Z}\s]*
size_t matchSoundEvent(std::u16string_view s, std::string* word);
// [\p{Z}\s]*(up|down|left|right|horizontal|vertical|orthogonal)(?![\p{L}\p{N}_])[\p{Z}\s]*
size_t matchSoundDirection(std::u16string_view s, std::string* word);
// (black|white|...|transparent|#(?:[0-9a-f]{3}){1,2})\s*
size_t matchColor(std::u16string_view s, std::string* word);

}  // namespace psc::parse
