#include "parse/LineCursor.h"

#include <array>

namespace psc::parse {
namespace {

using js::codePointAt;

// Length of the run of code points satisfying pred (the /u regexes see code points).
template <typename Pred>
size_t runOf(std::u16string_view s, size_t from, Pred pred) {
    size_t i = from;
    while (i < s.size()) {
        size_t units = 1;
        char32_t cp = codePointAt(s, i, &units);
        if (!pred(cp)) break;
        i += units;
    }
    return i - from;
}

size_t whitespaceRun(std::u16string_view s, size_t from) {
    return runOf(s, from, [](char32_t c) { return js::isSpaceOrSeparator(c); });
}

bool startsWith(std::u16string_view s, size_t at, std::string_view ascii) {
    if (s.size() < at + ascii.size()) return false;
    for (size_t i = 0; i < ascii.size(); ++i) {
        if (s[at + i] != static_cast<char16_t>(ascii[i])) return false;
    }
    return true;
}

// \b after a word character: the next code unit is not ASCII \w.
bool boundaryAfter(std::u16string_view s, size_t at) { return at >= s.size() || !js::isAsciiWordChar(s[at]); }

bool nameCharAt(std::u16string_view s, size_t at) {
    if (at >= s.size()) return false;
    size_t units = 1;
    return js::isNameChar(codePointAt(s, at, &units));
}

template <size_t N>
size_t matchAlternatives(std::u16string_view s, const std::array<std::string_view, N>& words, std::string* word,
                         bool (*followOk)(std::u16string_view, size_t)) {
    for (std::string_view w : words) {
        if (startsWith(s, 0, w) && followOk(s, w.size())) {
            if (word) *word = std::string(w);
            return w.size() + whitespaceRun(s, w.size());
        }
    }
    return kNoMatch;
}

bool notFollowedByNameChar(std::u16string_view s, size_t at) { return !nameCharAt(s, at); }

}  // namespace

void LineCursor::eatSpace() {
    while (!eol() && js::isSpace(text_[pos_])) ++pos_;
}

size_t matchName(std::u16string_view s) {
    size_t n = runOf(s, 0, js::isNameChar);
    if (n == 0) return kNoMatch;
    return n + whitespaceRun(s, n);
}

size_t matchSingleWord(std::u16string_view s) {
    size_t lead = whitespaceRun(s, 0);
    size_t n = runOf(s, lead, js::isNameChar);
    if (n == 0) return kNoMatch;
    return lead + n + whitespaceRun(s, lead + n);
}

size_t matchWordUntilSpaceOrParen(std::u16string_view s) {
    size_t n = runOf(s, 0, [](char32_t c) { return !js::isSpaceOrSeparator(c) && c != U'(' && c != U')'; });
    if (n == 0) return kNoMatch;
    return n + whitespaceRun(s, n);
}

size_t matchLegendKey(std::u16string_view s) {
    size_t n = runOf(s, 0, [](char32_t c) { return c != U'=' && c != U'(' && !js::isSpaceOrSeparator(c); });
    // (\p{Z}\s)*: pairs of a separator followed by a space character.
    while (n + 1 < s.size() && js::isSeparator(s[n]) && js::isSpace(s[n + 1])) n += 2;
    return n;
}

size_t matchUntilParen(std::u16string_view s) {
    size_t n = 0;
    while (n < s.size() && s[n] != u'(') ++n;
    return n == 0 ? kNoMatch : n;
}

size_t matchWhitespace(std::u16string_view s) { return whitespaceRun(s, 0); }

size_t matchLayerSeparators(std::u16string_view s) {
    size_t n = 0;
    while (n < s.size() && (s[n] == u' ' || s[n] == u',')) ++n;
    return n;
}

size_t matchEqualsRun(std::u16string_view s) {
    size_t n = 0;
    while (n < s.size() && s[n] == u'=') ++n;
    return n == 0 ? kNoMatch : n;
}

bool isEqualsLine(std::u16string_view s) {
    size_t n = runOf(s, 0, [](char32_t c) { return c == U'=' || js::isSpaceOrSeparator(c); });
    return n == s.size();
}

size_t matchRuleArrow(std::u16string_view s) {
    size_t lead = whitespaceRun(s, 0);
    if (!startsWith(s, lead, "->")) return kNoMatch;
    return lead + 2 + whitespaceRun(s, lead + 2);
}

size_t matchRulePart(std::u16string_view s) {
    return runOf(s, 0, [](char32_t c) { return c != U'[' && c != U'|' && c != U']' && !js::isSpaceOrSeparator(c); });
}

size_t matchSoundSeed(std::u16string_view s) {
    size_t n = 0;
    while (n < s.size() && s[n] >= u'0' && s[n] <= u'9') ++n;
    // Backtracking \d+ can end anywhere, but \b after a digit needs a non-word
    // character next, and shorter runs are followed by a digit: only the full run works.
    if (n == 0 || !boundaryAfter(s, n)) return kNoMatch;
    return n;
}

size_t matchMessageKeyword(std::u16string_view s, bool requireBoundary) {
    size_t lead = whitespaceRun(s, 0);
    if (!startsWith(s, lead, "message")) return kNoMatch;
    size_t end = lead + 7;
    if (requireBoundary && !boundaryAfter(s, end)) return kNoMatch;
    return end + whitespaceRun(s, end);
}

size_t matchSectionName(std::u16string_view s, std::string* word) {
    static constexpr std::array<std::string_view, 7> kWords = {"objects", "collisionlayers", "legend", "sounds",
                                                               "rules",   "winconditions",   "levels"};
    return matchAlternatives(s, kWords, word, notFollowedByNameChar);
}

size_t matchSoundVerb(std::u16string_view s, std::string* word) {
    static constexpr std::array<std::string_view, 5> kWords = {"move", "action", "create", "destroy", "cantmove"};
    return matchAlternatives(s, kWords, word, boundaryAfter);
}

size_t matchSoundEvent(std::u16string_view s, std::string* word) {
    static constexpr std::array<std::string_view, 21> kWords = {
        "undo", "restart", "titlescreen", "startgame", "cancel", "endgame", "startlevel",
        "endlevel", "showmessage", "closemessage", "sfx0", "sfx1", "sfx2", "sfx3",
        "sfx4", "sfx5", "sfx6", "sfx7", "sfx8", "sfx9", "sfx10"};
    return matchAlternatives(s, kWords, word, boundaryAfter);
}

size_t matchSoundDirection(std::u16string_view s, std::string* word) {
    static constexpr std::array<std::string_view, 7> kWords = {"up", "down", "left", "right",
                                                               "horizontal", "vertical", "orthogonal"};
    size_t lead = whitespaceRun(s, 0);
    size_t n = matchAlternatives(s.substr(lead), kWords, word, notFollowedByNameChar);
    return n == kNoMatch ? kNoMatch : lead + n;
}

size_t matchColor(std::u16string_view s, std::string* word) {
    static constexpr std::array<std::string_view, 25> kNames = {
        "black", "white", "gray", "darkgray", "lightgray", "grey", "darkgrey", "lightgrey", "red",
        "darkred", "lightred", "brown", "darkbrown", "lightbrown", "orange", "yellow", "green",
        "darkgreen", "lightgreen", "blue", "lightblue", "darkblue", "purple", "pink", "transparent"};
    auto spaceRun = [&](size_t from) {
        size_t i = from;
        while (i < s.size() && js::isSpace(s[i])) ++i;
        return i;
    };
    for (std::string_view w : kNames) {
        if (startsWith(s, 0, w)) {
            if (word) *word = std::string(w);
            return spaceRun(w.size());
        }
    }
    auto isHex = [&](size_t i) {
        return i < s.size() && ((s[i] >= u'0' && s[i] <= u'9') || (s[i] >= u'a' && s[i] <= u'f'));
    };
    if (!s.empty() && s[0] == u'#' && isHex(1) && isHex(2) && isHex(3)) {
        size_t end = (isHex(4) && isHex(5) && isHex(6)) ? 7 : 4;
        if (word) *word = js::toUtf8(s.substr(0, end));
        return spaceRun(end);
    }
    return kNoMatch;
}

}  // namespace psc::parse
