#include "parse/Scanner.h"

#include <algorithm>
#include <functional>
#include <optional>
#include <set>
#include <unordered_set>

#include "parse/LineCursor.h"

namespace psc::parse {

const char* const kSectionNames[7] = {"objects", "legend", "sounds", "collisionlayers",
                                      "rules",   "winconditions", "levels"};

namespace {

using js::toUpperAscii;
using js::toUtf8;
using js::U16;

const std::unordered_set<std::string> kKeywords = {
    "objects", "collisionlayers", "legend", "sounds", "rules", "...", "winconditions", "levels", "|", "[",
    "]", "up", "down", "left", "right", "late", "rigid", "^", "v", ">", "<", "no", "randomdir", "random",
    "horizontal", "vertical", "any", "all", "some", "moving", "stationary", "parallel", "perpendicular",
    "action", "message", "move", "create", "destroy", "cantmove", "sfx0", "sfx1", "sfx2", "sfx3", "sfx4",
    "sfx5", "sfx6", "sfx7", "sfx8", "sfx9", "sfx10", "cancel", "restart", "win", "again", "undo",
    "titlescreen", "startgame", "endgame", "startlevel", "endlevel", "showmessage", "closemessage"};

const std::unordered_set<std::string> kCommandWords = {"sfx0", "sfx1", "sfx2", "sfx3", "sfx4", "sfx5",
                                                       "sfx6", "sfx7", "sfx8", "sfx9", "sfx10", "cancel",
                                                       "checkpoint", "restart", "win", "message", "again"};

const std::unordered_set<std::string> kMetadataWithValue = {
    "title", "author", "homepage", "background_color", "text_color", "key_repeat_interval",
    "realtime_interval", "again_interval", "flickscreen", "zoomscreen", "color_palette", "youtube"};
const std::unordered_set<std::string> kMetadataFlags = {
    "run_rules_on_level_start", "norepeat_action", "require_player_movement", "debug", "verbose_logging",
    "throttle_movement", "noundo", "noaction", "norestart", "scanline"};

const std::unordered_set<std::string> kRulePrefixWords = {"up", "down", "left", "right", "horizontal",
                                                          "vertical", "orthogonal", "late", "rigid"};
const std::unordered_set<std::string> kCellModifiers = {
    "action", "up", "down", "left", "right", "^", "v", "<", ">", "moving", "stationary", "parallel",
    "perpendicular", "horizontal", "orthogonal", "vertical", "no", "randomdir", "random"};
const std::unordered_set<std::string> kWinQuantifiers = {"all", "any", "no", "some"};

enum class Section { Prelude, Objects, Legend, Sounds, CollisionLayers, Rules, WinConditions, Levels };

Section sectionFromName(const std::string& name) {
    if (name == "objects") return Section::Objects;
    if (name == "legend") return Section::Legend;
    if (name == "sounds") return Section::Sounds;
    if (name == "collisionlayers") return Section::CollisionLayers;
    if (name == "rules") return Section::Rules;
    if (name == "winconditions") return Section::WinConditions;
    return Section::Levels;
}

// What the object section expects next: a name, the colour line, or sprite rows.
enum class ObjectPart { Name = 0, NameSeen = 1, Colors = 2, Sprite = 3 };

// One word collected from a sound line, or a marker that the line went wrong.
using SoundSlot = std::optional<ast::SoundWord>;

class Scanner {
public:
    explicit Scanner(Diagnostics& d) : diag_(d) {}

    ast::Game run(std::string_view source);

private:
    void token(LineCursor& s, const U16& lineAsWritten);
    void endOfLine();
    void blankLine();
    void readSectionHeader(const std::string& name);

    void objectsToken(LineCursor& s, bool sol);
    void objectName(LineCursor& s, bool sol);
    void legendToken(LineCursor& s);
    void soundsToken(LineCursor& s);
    void layersToken(LineCursor& s, bool sol);
    void rulesToken(LineCursor& s, bool sol, int firstChar, const U16& mixedCase);
    void winConditionsToken(LineCursor& s, bool sol);
    bool levelsToken(LineCursor& s, bool sol, const U16& mixedCase);
    bool preludeToken(LineCursor& s, bool sol, const U16& mixedCase);

    void finishLegendLine();
    void finishSoundLine();

    // The reference's name lookups (each list searched from its start).
    const void* declaration(const std::string& name, int* line) const;
    bool declared(const std::string& name) const { return declaration(name, nullptr) != nullptr; }
    struct Lookup {
        enum class Kind { Object, Aggregate, Property, Undeclared } kind;
        std::string name;
        const ast::LegendDecl* entry = nullptr;
    };
    Lookup lookup(const std::string& name, int depth = 0) const;
    std::vector<std::string> flattenProperty(const ast::LegendDecl& entry,
                                             const std::function<std::vector<std::string>(const std::string&)>& sub);

    void error(const std::string& message, const LineCursor* s = nullptr) {
        diag_.error(line_, message, s ? static_cast<int>(s->pos()) + 1 : 0);
    }
    void warning(const std::string& message, const LineCursor* s = nullptr) {
        diag_.warning(line_, message, s ? static_cast<int>(s->pos()) + 1 : 0);
    }

    Diagnostics& diag_;
    ast::Game game_;

    int line_ = 0;
    int commentDepth_ = 0;
    int commentOpenedOn_ = 0;  // line of the outermost open comment
    Section section_ = Section::Prelude;
    bool sectionSeen_ = false;
    std::vector<std::string> visited_;
    bool lineShouldEnd_ = false;
    std::string lineShouldEndBecause_;
    bool solAfterComment_ = false;
    int tokenIndex_ = 0;

    std::string currentObject_;
    ObjectPart objectPart_ = ObjectPart::Name;
    std::vector<std::string> pendingSprite_;

    std::vector<std::string> legendWords_;
    std::vector<SoundSlot> soundWords_;
    std::vector<std::string> layerLineNames_;

    std::set<std::u16string> glyphs_;    // one-code-unit names, fixed when LEVELS starts
};

ast::Game Scanner::run(std::string_view source) {
    U16 text = js::fromUtf8(source);
    game_.levels.push_back(ast::LevelSource{});
    size_t start = 0;
    while (true) {
        size_t end = text.find(u'\n', start);
        const U16 line = text.substr(start, end == U16::npos ? U16::npos : end - start);
        LineCursor cursor(line);
        do {
            size_t before = cursor.pos();
            bool wasSol = cursor.sol();
            token(cursor, line);
            if (diag_.errorCount() > kMaxParseErrors) throw ParseGaveUp{};
            // Every token consumes input in the reference; never loop in place.
            if (cursor.pos() == before && !cursor.eol() && !wasSol) cursor.next();
        } while (!cursor.eol());
        if (end == U16::npos) break;
        start = end + 1;
    }
    if (commentDepth_ > 0) {
        diag_.warning(commentOpenedOn_, "this comment is never closed; everything after it is ignored");
    }
    return std::move(game_);
}

void Scanner::token(LineCursor& s, const U16& lineAsWritten) {
    // The reference keeps "the line as the token saw it": as written on the
    // first token of a line, lower case (or as rewritten) afterwards.
    bool sol = s.sol();
    const U16& mixedCase = sol ? lineAsWritten : s.text();
    if (sol) {
        ++line_;
        legendWords_.clear();
        soundWords_.clear();
        s.replaceText(js::toLower(s.text()));
        tokenIndex_ = 0;
        lineShouldEnd_ = false;
    }
    if (solAfterComment_) {
        sol = true;
        solAfterComment_ = false;
    }

    s.eatSpace();

    // Comments: '(' opens, ')' closes, they nest and may span lines.
    int ch = s.peek();
    if (ch == u'(' && tokenIndex_ != -4) {
        s.next();
        if (commentDepth_++ == 0) commentOpenedOn_ = line_;
    } else if (ch == u')') {
        s.next();
        if (commentDepth_ > 0) {
            --commentDepth_;
            if (commentDepth_ == 0) {
                solAfterComment_ = true;
                return;
            }
        } else {
            warning("')' closes a comment that was never opened", &s);
            return;
        }
    }
    if (commentDepth_ > 0) {
        if (sol) solAfterComment_ = true;
        while (true) {
            while (!s.eol() && s.peek() != u'(' && s.peek() != u')') s.next();
            if (s.eol()) break;
            if (s.peek() == u'(') ++commentDepth_;
            else --commentDepth_;
            s.next();
            if (commentDepth_ == 0) break;
        }
        if (s.eol()) endOfLine();
        return;
    }

    s.eatSpace();
    if (sol && s.eol()) {
        endOfLine();
        blankLine();
        return;
    }
    if (lineShouldEnd_ && !s.eol()) {
        error("only a comment may follow " + lineShouldEndBecause_ + " on a line", &s);
        s.skipToEnd();
        return;
    }

    // A row of '=' separates sections; in LEVELS only a row of nothing else counts ('=' can be a glyph).
    bool equalsCanEndLine = !(sol && section_ == Section::Levels && !isEqualsLine(s.rest()));
    if (sol && equalsCanEndLine && s.consume(matchEqualsRun(s.rest())) != kNoMatch) {
        lineShouldEnd_ = true;
        lineShouldEndBecause_ = "a row of '='";
        return;
    }

    // Section words are consumed wherever they appear before LEVELS; only at the start of a line are they headers.
    if (section_ != Section::Levels) {
        std::string name;
        size_t n = s.consume(matchSectionName(s.rest(), &name));
        if (sol && n != kNoMatch) {
            readSectionHeader(name);
            return;
        }
    }

    if (s.eol()) {
        endOfLine();
        return;
    }

    bool handled = true;
    switch (section_) {
        case Section::Objects: objectsToken(s, sol); break;
        case Section::Legend: legendToken(s); break;
        case Section::Sounds:
            soundsToken(s);
            if (s.eol()) finishSoundLine();
            break;
        case Section::CollisionLayers: layersToken(s, sol); break;
        case Section::Rules: rulesToken(s, sol, ch, mixedCase); break;
        case Section::WinConditions: winConditionsToken(s, sol); break;
        case Section::Levels: handled = levelsToken(s, sol, mixedCase); break;
        case Section::Prelude: handled = preludeToken(s, sol, mixedCase); break;
    }
    if (!handled) s.next();
}

void Scanner::endOfLine() {
    if (section_ == Section::Legend) finishLegendLine();
    else if (section_ == Section::Sounds) finishSoundLine();
}

void Scanner::blankLine() {
    if (section_ == Section::Levels) {
        if (!game_.levels.back().isMessage && !game_.levels.back().rows.empty()) game_.levels.push_back({});
        else if (game_.levels.back().isMessage) game_.levels.push_back({});
    }
    if (section_ == Section::Objects) objectPart_ = ObjectPart::Name;
}

void Scanner::readSectionHeader(const std::string& name) {
    bool duplicate = std::find(visited_.begin(), visited_.end(), name) != visited_.end();
    section_ = sectionFromName(name);
    sectionSeen_ = true;
    if (duplicate) error("section " + toUpperAscii(name) + " appears twice");
    lineShouldEnd_ = true;
    lineShouldEndBecause_ = "the section name " + toUpperAscii(name);
    visited_.push_back(name);
    int index = 0;
    while (kSectionNames[index] != name) ++index;
    if (index == 0) {
        objectPart_ = ObjectPart::Name;
        if (visited_.size() > 1) error("section OBJECTS must be the first section");
    } else if (std::find(visited_.begin(), visited_.end(), kSectionNames[index - 1]) == visited_.end()) {
        error("section " + toUpperAscii(name) + " is out of order: it must follow section " +
              toUpperAscii(kSectionNames[index - 1]) + " (every section heading is required, even for an empty section)");
    }
    if (section_ == Section::Sounds) {
        for (const auto& o : game_.objects) game_.ruleNames.insert(o.name);
        for (const auto* list : {&game_.synonyms, &game_.aggregates, &game_.properties}) {
            for (const auto& e : *list) game_.ruleNames.insert(e.name);
        }
    } else if (section_ == Section::Levels) {
        auto addGlyph = [&](const std::string& n) {
            U16 u = js::fromUtf8(n);
            if (u.size() == 1) glyphs_.insert(u);
        };
        for (const auto& o : game_.objects) addGlyph(o.name);
        for (const auto& e : game_.synonyms) addGlyph(e.name);
        for (const auto& e : game_.aggregates) addGlyph(e.name);
    }
}

// ---------------------------------------------------------------- names

const void* Scanner::declaration(const std::string& name, int* line) const {
    if (const ast::ObjectDecl* o = game_.findObject(name)) {
        if (line) *line = o->line;
        return o;
    }
    for (const auto* list : {&game_.aggregates, &game_.properties, &game_.synonyms}) {
        for (const auto& e : *list) {
            if (e.name == name) {
                if (line) *line = e.line;
                return &e;
            }
        }
    }
    return nullptr;
}

Scanner::Lookup Scanner::lookup(const std::string& name, int depth) const {
    // A synonym cycle makes the reference recurse until its stack overflows.
    if (depth > 10000) throw CompileAborted("legend definitions refer to each other in a cycle");
    if (game_.findObject(name)) return {Lookup::Kind::Object, name};
    for (const auto& e : game_.synonyms) {
        if (e.name == name) return lookup(e.members[0], depth + 1);
    }
    for (const auto& e : game_.aggregates) {
        if (e.name == name) return {Lookup::Kind::Aggregate, name, &e};
    }
    for (const auto& e : game_.properties) {
        if (e.name == name) return {Lookup::Kind::Property, name, &e};
    }
    return {Lookup::Kind::Undeclared, name};
}

std::vector<std::string> Scanner::flattenProperty(
    const ast::LegendDecl& entry, const std::function<std::vector<std::string>(const std::string&)>& sub) {
    std::vector<std::string> out;
    for (const auto& m : entry.members) {
        if (m == entry.name) continue;
        auto part = sub(m);
        out.insert(out.end(), part.begin(), part.end());
    }
    return out;
}

// ---------------------------------------------------------------- OBJECTS

void Scanner::objectsToken(LineCursor& s, bool sol) {
    if (sol && objectPart_ == ObjectPart::Colors) objectPart_ = ObjectPart::Sprite;
    if (sol && objectPart_ == ObjectPart::NameSeen) objectPart_ = ObjectPart::Colors;

    switch (objectPart_) {
        case ObjectPart::Name:
        case ObjectPart::NameSeen:
            pendingSprite_.clear();
            objectName(s, sol);
            return;
        case ObjectPart::Colors: {
            tokenIndex_ = 0;
            std::string color;
            size_t n = s.consume(matchColor(s.rest(), &color));
            if (n == kNoMatch) {
                size_t m = matchName(s.rest());
                if (m == kNoMatch) m = matchUntilParen(s.rest());
                std::string found = m == kNoMatch ? std::string() : toUtf8(js::trim(s.rest().substr(0, m)));
                s.consume(m);
                error("expected a colour for object " + toUpperAscii(currentObject_) + ", found \"" + found + "\"");
                return;
            }
            game_.objects[game_.objectIndex.at(currentObject_)].colors.push_back(color);
            return;
        }
        case ObjectPart::Sprite: {
            int c = s.peek();
            bool pixel = c == u'.' || (c >= u'0' && c <= u'9');
            if (!pixel) {
                if (pendingSprite_.empty()) {
                    objectName(s, sol);
                    return;
                }
                error("unexpected text in the sprite of object " + toUpperAscii(currentObject_), &s);
                s.consume(matchUntilParen(s.rest()));
                return;
            }
            s.next();
            if (sol) pendingSprite_.emplace_back();
            if (pendingSprite_.empty()) {
                // A pixel after an object's name on its own line ("g."): there
                // is no sprite row to extend, and the reference reports the
                // sprite's size (tests/fuzz/regressions/frontend/sprite-pixel-after-name).
                warning("sprites must be 5 pixels wide and 5 high", &s);
                s.consume(matchUntilParen(s.rest()));
                return;
            }
            ast::ObjectDecl& object = game_.objects[game_.objectIndex.at(currentObject_)];
            pendingSprite_.back().push_back(static_cast<char>(c));
            object.spriteRows = pendingSprite_;
            if (pendingSprite_.back().size() > 5) {
                warning("sprites must be 5 pixels wide and 5 high", &s);
                s.consume(matchUntilParen(s.rest()));
                return;
            }
            if (pendingSprite_.size() == 5 && pendingSprite_.back().size() == 5) objectPart_ = ObjectPart::Name;
            if (c != u'.') {
                size_t colorIndex = static_cast<size_t>(c - u'0');
                if (colorIndex >= object.colors.size()) {
                    error("sprite of " + toUpperAscii(currentObject_) + " uses colour " + std::to_string(colorIndex) +
                              ", but its palette has only " + std::to_string(object.colors.size()) + " colours",
                          &s);
                }
            }
            return;
        }
    }
}

void Scanner::objectName(LineCursor& s, bool sol) {
    size_t n = s.consume(sol ? matchName(s.rest()) : matchWordUntilSpaceOrParen(s.rest()));
    if (n == kNoMatch) {
        s.consume(matchUntilParen(s.rest()));
        if (s.pos() > 0) {
            warning("unexpected text in the OBJECTS section (object names are letters, digits and '_'; "
                    "sprites are 5 rows of 5 pixels)", &s);
        }
        return;
    }
    std::string name = toUtf8(js::trim(std::u16string_view(s.text()).substr(s.pos() - n, n)));
    if (game_.findObject(name)) {
        error("object " + toUpperAscii(name) + " is defined more than once", &s);
        return;
    }
    for (const auto& e : game_.synonyms) {
        if (e.name == name) error("the name " + toUpperAscii(name) + " is already in use", &s);
    }
    if (kKeywords.count(name)) warning("object " + toUpperAscii(name) + " is named after a keyword; avoid that", &s);
    game_.nameLines[name] = line_;
    if (!sol && currentObject_.empty()) {
        // A second name on a line whose first was not an object's (the
        // reference fails on the colours that follow, tests/fuzz/regressions/
        // frontend/name-before-any-object): there is no object to alias.
        error("the name " + toUpperAscii(name) + " follows no object: an object's first name starts its line", &s);
        return;
    }
    if (sol) {
        currentObject_ = name;
        game_.objectIndex[name] = game_.objects.size();
        game_.objects.push_back(ast::ObjectDecl{name, line_, {}, {}});
    } else {
        game_.synonyms.push_back(ast::LegendDecl{ast::LegendDecl::Kind::Synonym, name, {currentObject_}, line_});
    }
    objectPart_ = ObjectPart::NameSeen;
}

// ---------------------------------------------------------------- LEGEND

void Scanner::legendToken(LineCursor& s) {
    std::optional<std::string> word;
    auto textOf = [&](size_t n) { return toUtf8(js::trim(std::u16string_view(s.text()).substr(s.pos() - n, n))); };
    if (tokenIndex_ == 0) {
        size_t n = s.consume(matchLegendKey(s.rest()));
        word = textOf(n);
        ++tokenIndex_;
    } else if (tokenIndex_ == 1) {
        size_t n = s.consume(s.peek() == u'=' ? 1 : kNoMatch);
        if (n == kNoMatch) {
            error("legend lines define names with '=': \"A = B\", \"A = B or C ...\" or \"A = B and C ...\"", &s);
            s.consume(matchUntilParen(s.rest()));
            word = "ERROR";
        } else {
            word = "=";
        }
        s.consume(matchWhitespace(s.rest()));
        ++tokenIndex_;
    } else if (tokenIndex_ >= 3 && tokenIndex_ % 2 == 1) {
        size_t n = s.consume(matchName(s.rest()));
        if (n == kNoMatch) {
            error("unexpected text in the legend", &s);
            s.consume(matchUntilParen(s.rest()));
        } else {
            word = textOf(n);
            if (*word == "and" || *word == "or") {
                if (tokenIndex_ >= 5 && *word != legendWords_[3]) {
                    error("a legend line cannot mix AND and OR", &s);
                }
            } else {
                error("expected AND or OR here, found " + toUpperAscii(*word), &s);
            }
        }
        ++tokenIndex_;
    } else {
        size_t n = s.consume(matchName(s.rest()));
        if (n == kNoMatch) {
            error("unexpected text in the legend", &s);
            s.consume(matchUntilParen(s.rest()));
        } else {
            word = textOf(n);
            ++tokenIndex_;
        }
    }
    if (word) legendWords_.push_back(*word);
    if (s.eol()) finishLegendLine();
}

void Scanner::finishLegendLine() {
    std::vector<std::string>& words = legendWords_;
    if (words.empty()) return;
    const std::string shape = "a legend line is \"A = B\", \"A = B or C ...\" or \"A = B and C ...\"";
    if (words.size() == 1) {
        error("malformed legend line: " + shape);
        return;
    }
    if (words.size() % 2 == 0) {
        error("malformed legend line: " + shape + "; \"" + toUpperAscii(words.back()) + "\" is left over");
        return;
    }
    bool ok = true;
    const std::string name = words[0];
    int previousLine = 0;
    if (declaration(name, &previousLine)) {
        error("the name " + toUpperAscii(name) + " is already in use (line " + std::to_string(previousLine) + ")");
        ok = false;
    }
    if (kKeywords.count(name)) warning("object " + toUpperAscii(name) + " is named after a keyword; avoid that");
    for (size_t i = 2; i < words.size(); i += 2) {
        const std::string member = words[i];
        if (member == name) {
            error("cannot define " + toUpperAscii(name) + " in terms of itself");
            ok = false;
            auto next = [&]() {
                auto it = std::find(words.begin() + std::min<size_t>(2, words.size()), words.end(), name);
                return it == words.end() ? -1 : static_cast<long>(it - words.begin());
            };
            for (long at = next(); at >= 2; at = next()) {
                if (at >= 4) words.erase(words.begin() + at - 1, words.begin() + at + 1);
                else words.erase(words.begin() + at, words.begin() + std::min<long>(at + 2, words.size()));
            }
        }
        for (size_t j = 2; j < i && j < words.size(); j += 2) {
            if (words[j] == member) warning("the object " + toUpperAscii(member) + " is repeated on the right-hand side");
        }
    }
    for (size_t i = 2; i < words.size(); i += 2) {
        if (words[i] != name && !declared(words[i])) {
            error("the name " + toUpperAscii(words[i]) + " is used but never defined");
        }
    }

    if (words.size() == 3) {
        game_.synonyms.push_back(ast::LegendDecl{ast::LegendDecl::Kind::Synonym, name, {words[2]}, line_});
        game_.nameLines[name] = line_;
    } else if (words.size() > 3 && words[3] == "and") {
        std::function<std::vector<std::string>(const std::string&)> parts = [&](const std::string& n) {
            Lookup found = lookup(n);
            switch (found.kind) {
                case Lookup::Kind::Aggregate: {
                    std::vector<std::string> out;
                    for (const auto& m : found.entry->members) {
                        auto p = parts(m);
                        out.insert(out.end(), p.begin(), p.end());
                    }
                    return out;
                }
                case Lookup::Kind::Property:
                    error("an aggregate (defined with AND) cannot be made of properties (defined with OR)");
                    ok = false;
                    return std::vector<std::string>{found.name};
                default:
                    return std::vector<std::string>{found.name};
            }
        };
        ast::LegendDecl decl{ast::LegendDecl::Kind::Aggregate, name, {}, line_};
        for (size_t i = 2; i < words.size(); i += 2) {
            auto p = parts(words[i]);
            decl.members.insert(decl.members.end(), p.begin(), p.end());
        }
        game_.aggregates.push_back(std::move(decl));
        game_.nameLines[name] = line_;
    } else if (words.size() > 3 && words[3] == "or") {
        for (size_t i = 5; i < words.size(); i += 2) {
            if (words[i] != "or") return;  // mixed connectives were reported word by word
        }
        std::function<std::vector<std::string>(const std::string&)> members = [&](const std::string& n) {
            Lookup found = lookup(n);
            switch (found.kind) {
                case Lookup::Kind::Aggregate:
                    error("property " + toUpperAscii(name) + " (defined with OR) cannot include the aggregate " +
                          toUpperAscii(found.name) + " (defined with AND)");
                    return std::vector<std::string>{};
                case Lookup::Kind::Property:
                    return flattenProperty(*found.entry, members);
                default:
                    return std::vector<std::string>{found.name};
            }
        };
        ast::LegendDecl decl{ast::LegendDecl::Kind::Property, name, {}, line_};
        for (size_t i = 2; i < words.size(); i += 2) {
            auto p = members(words[i]);
            decl.members.insert(decl.members.end(), p.begin(), p.end());
        }
        if (!decl.members.empty()) {
            game_.properties.push_back(std::move(decl));
            game_.nameLines[name] = line_;
        }
    } else if (ok) {
        error("malformed legend line: " + shape);
    }
}

// ---------------------------------------------------------------- SOUNDS

void Scanner::soundsToken(LineCursor& s) {
    using Kind = ast::SoundWord::Kind;
    auto text = [&](size_t n) { return toUtf8(js::trim(std::u16string_view(s.text()).substr(s.pos() - n, n))); };
    auto fallback = [&]() {
        size_t n = s.consume(matchWordUntilSpaceOrParen(s.rest()));
        if (n == kNoMatch) n = s.consume(matchUntilParen(s.rest()));
        return n == kNoMatch ? std::string() : text(n);
    };
    auto fail = [&]() { soundWords_.push_back(std::nullopt); };

    if (!soundWords_.empty() && !soundWords_.back().has_value()) {
        // After a mistake the rest of the line is read word by word without checks.
        std::string w;
        if (s.consume(matchSoundEvent(s.rest(), &w)) != kNoMatch) return;
        if (s.consume(matchSoundVerb(s.rest(), &w)) != kNoMatch) return;
        if (s.consume(matchSoundDirection(s.rest(), &w)) != kNoMatch) return;
        // (a seed here is matched but, as in the reference, does not stop the search)
        s.consume(matchSoundSeed(s.rest()));
        size_t n = s.consume(matchName(s.rest()));
        if (n == kNoMatch) fallback();
        return;
    }
    if (soundWords_.empty()) {
        std::string w;
        size_t n = s.consume(matchSoundEvent(s.rest(), &w));
        if (n != kNoMatch) {
            soundWords_.push_back(ast::SoundWord{Kind::Event, w});
            ++tokenIndex_;
            return;
        }
        n = s.consume(matchName(s.rest()));
        if (n == kNoMatch) {
            fallback();
            fail();
            warning("expected a sound event (such as SFX3 or ENDLEVEL) or an object name", &s);
            return;
        }
        std::string name = text(n);
        if (!declared(name)) {
            fail();
            error("unexpected word \"" + name + "\" in a sound declaration", &s);
        } else {
            soundWords_.push_back(ast::SoundWord{Kind::Name, name});
            ++tokenIndex_;
        }
        return;
    }
    const ast::SoundWord& first = *soundWords_.front();
    const std::string lastText = soundWords_.back()->text;
    if (soundWords_.size() == 1) {
        if (first.kind == Kind::Event) {
            size_t n = s.consume(matchSoundSeed(s.rest()));
            if (n != kNoMatch) {
                soundWords_.push_back(ast::SoundWord{Kind::Seed, text(n)});
                ++tokenIndex_;
            } else {
                fallback();
                error("expected a sound seed (a number) here", &s);
                fail();
            }
        } else {
            std::string w;
            size_t n = s.consume(matchSoundVerb(s.rest(), &w));
            if (n != kNoMatch) {
                soundWords_.push_back(ast::SoundWord{Kind::Verb, w});
                ++tokenIndex_;
            } else {
                fallback();
                error("expected a sound verb (MOVE, ACTION, CREATE, DESTROY or CANTMOVE) here", &s);
                fail();
            }
        }
        return;
    }
    if (first.kind == Kind::Event || soundWords_.back()->kind == Kind::Seed) {
        std::string extra = fallback();
        error("nothing may follow the sound declaration " + toUpperAscii(lastText) + ", found \"" +
                  toUpperAscii(extra) + "\"", &s);
        fail();
        return;
    }
    bool directional = soundWords_[1]->text == "move" || soundWords_[1]->text == "cantmove";
    if (directional) {
        std::string w;
        size_t n = s.consume(matchSoundDirection(s.rest(), &w));
        if (n != kNoMatch) {
            soundWords_.push_back(ast::SoundWord{Kind::Direction, w});
            ++tokenIndex_;
            return;
        }
    }
    size_t n = s.consume(matchSoundSeed(s.rest()));
    if (n != kNoMatch) {
        soundWords_.push_back(ast::SoundWord{Kind::Seed, text(n)});
        ++tokenIndex_;
        return;
    }
    std::string extra = fallback();
    error(std::string(directional ? "expected a direction or a sound seed" : "expected a sound seed") + " after " +
              toUpperAscii(lastText) + ", found \"" + toUpperAscii(extra) + "\"", &s);
    fail();
}

void Scanner::finishSoundLine() {
    if (soundWords_.empty() || !soundWords_.back().has_value()) return;
    ast::SoundDecl decl{{}, line_};
    for (const auto& w : soundWords_) decl.words.push_back(*w);
    game_.sounds.push_back(std::move(decl));
}

// ---------------------------------------------------------------- COLLISIONLAYERS

void Scanner::layersToken(LineCursor& s, bool sol) {
    if (sol) {
        game_.collisionLayers.emplace_back();
        layerLineNames_.clear();
        tokenIndex_ = 0;
    }
    size_t n = s.consume(matchName(s.rest()));
    if (n == kNoMatch) {
        size_t before = s.pos();
        s.consume(matchLayerSeparators(s.rest()));
        if (s.pos() == before) {
            error("unexpected character '" + toUtf8(std::u16string(1, static_cast<char16_t>(s.peek()))) +
                  "' in a collision layer", &s);
            s.next();
        }
        return;
    }
    std::string name = toUtf8(js::trim(std::u16string_view(s.text()).substr(s.pos() - n, n)));
    std::function<std::vector<std::string>(const std::string&)> objectsOf = [&](const std::string& n2) {
        Lookup found = lookup(n2);
        switch (found.kind) {
            case Lookup::Kind::Object: return std::vector<std::string>{found.name};
            case Lookup::Kind::Aggregate:
                error("\"" + found.name + "\" is an aggregate (defined with AND); its objects must coexist, so it "
                      "cannot go in one collision layer", &s);
                return std::vector<std::string>{};
            case Lookup::Kind::Property: return flattenProperty(*found.entry, objectsOf);
            default:
                error("cannot add " + toUpperAscii(name) + " to a collision layer: it is not defined", &s);
                return std::vector<std::string>{};
        }
    };
    if (name == "background") {
        if (!game_.collisionLayers.empty() && !game_.collisionLayers.back().empty()) {
            error("BACKGROUND must be alone in its collision layer", &s);
        }
        tokenIndex_ = 1;
    } else if (tokenIndex_ != 0) {
        error("BACKGROUND must be alone in its collision layer", &s);
    }
    std::vector<std::string> objects = objectsOf(name);
    if (game_.collisionLayers.empty()) {
        // Only a line's first token starts a layer; a stray ')' can take that place.
        error("no collision layer to add " + toUpperAscii(name) + " to: a layer starts at the beginning of a line", &s);
        return;
    }

    std::vector<size_t> otherLayers;
    for (const auto& o : objects) {
        for (size_t j = 0; j + 1 < game_.collisionLayers.size(); ++j) {
            const auto& layer = game_.collisionLayers[j];
            if (std::find(layer.begin(), layer.end(), o) != layer.end()) otherLayers.push_back(j);
        }
    }
    if (!otherLayers.empty()) {
        std::string list;
        for (size_t j : otherLayers) list += "#" + std::to_string(j + 1) + ", ";
        list += "#" + std::to_string(game_.collisionLayers.size());
        warning("object " + toUpperAscii(name) + " is in several collision layers (" + list + ")", &s);
    }
    if (std::find(layerLineNames_.begin(), layerLineNames_.end(), name) != layerLineNames_.end()) {
        warning("object " + toUpperAscii(name) + " is listed twice in the same collision layer", &s);
    }
    layerLineNames_.push_back(name);
    auto& layer = game_.collisionLayers.back();
    layer.insert(layer.end(), objects.begin(), objects.end());
}

// ---------------------------------------------------------------- RULES

void Scanner::rulesToken(LineCursor& s, bool sol, int firstChar, const U16& mixedCase) {
    if (sol) {
        // The rule is the first run of text without '(' anywhere in the line.
        const U16& t = s.text();
        size_t b = t.find_first_not_of(u'(');
        size_t e = b == U16::npos ? U16::npos : t.find(u'(', b);
        U16 text = b == U16::npos ? U16() : t.substr(b, e == U16::npos ? U16::npos : e - b);
        game_.rules.push_back(ast::RuleLineSource{text, mixedCase, line_});
        tokenIndex_ = 0;
    }
    if (tokenIndex_ == -4) {
        s.skipToEnd();
        return;
    }
    if (s.consume(matchRuleArrow(s.rest())) != kNoMatch) return;
    if (firstChar == u'[' || firstChar == u'|' || firstChar == u']' || firstChar == u'+') {
        if (firstChar != u'+') tokenIndex_ = 1;
        s.next();
        s.consume(matchWhitespace(s.rest()));
        return;
    }
    size_t n = s.consume(matchRulePart(s.rest()));
    std::string word = toUtf8(js::trim(std::u16string_view(s.text()).substr(s.pos() - n, n)));
    if (tokenIndex_ == 0 && (word == "startloop" || word == "endloop")) return;
    if (tokenIndex_ == 0 && kRulePrefixWords.count(word)) {
        s.consume(matchWhitespace(s.rest()));
        return;
    }
    if (tokenIndex_ == 1 && kCellModifiers.count(word)) {
        s.consume(matchWhitespace(s.rest()));
        return;
    }
    if (game_.ruleNames.count(word)) {
        if (sol) {
            error("objects can only appear inside square brackets in rules; only directions may come before them", &s);
        } else {
            s.consume(matchWhitespace(s.rest()));
        }
        return;
    }
    if (word == "..." || word == "rigid" || word == "random") return;
    if (kCommandWords.count(word)) {
        if (word == "message") tokenIndex_ = -4;
        return;
    }
    error("the name \"" + word + "\" used in this rule is not defined", &s);
}

// ---------------------------------------------------------------- WINCONDITIONS

void Scanner::winConditionsToken(LineCursor& s, bool sol) {
    if (sol) {
        const U16& t = s.text();
        size_t b = t.find_first_not_of(u'(');
        size_t e = b == U16::npos ? U16::npos : t.find(u'(', b);
        U16 text = b == U16::npos ? U16() : t.substr(b, e == U16::npos ? U16::npos : e - b);
        ast::WinConditionSource w{{}, line_};
        size_t i = 0;
        while (i <= text.size()) {
            size_t j = i;
            while (j < text.size() && !js::isSpaceOrSeparator(text[j])) ++j;
            if (j > i) w.words.push_back(toUtf8(std::u16string_view(text).substr(i, j - i)));
            i = j + 1;
        }
        game_.winConditions.push_back(std::move(w));
        tokenIndex_ = -1;
    }
    ++tokenIndex_;
    size_t n = s.consume(matchSingleWord(s.rest()));
    if (n == kNoMatch) {
        error("malformed win condition", &s);
        s.consume(matchUntilParen(s.rest()));
        return;
    }
    std::string word = toUtf8(js::trim(std::u16string_view(s.text()).substr(s.pos() - n, n)));
    if (tokenIndex_ == 0) {
        if (!kWinQuantifiers.count(word)) {
            error("a win condition starts with ALL, SOME, ANY or NO, not " + toUpperAscii(word), &s);
        }
    } else if (tokenIndex_ == 2) {
        if (word != "on") error("expected ON here, found " + toUpperAscii(word), &s);
    } else if (tokenIndex_ == 1 || tokenIndex_ == 3) {
        if (!game_.ruleNames.count(word)) error("win condition names " + toUpperAscii(word) + ", which is not an object", &s);
    } else {
        error("unexpected " + toUpperAscii(word) + " at the end of a win condition", &s);
    }
}

// ---------------------------------------------------------------- LEVELS

bool Scanner::levelsToken(LineCursor& s, bool sol, const U16& mixedCase) {
    if (sol) {
        size_t n = s.consume(matchMessageKeyword(s.rest(), true));
        bool message = n != kNoMatch;
        if (!message && s.consume(matchMessageKeyword(s.rest(), false)) != kNoMatch) {
            warning("'message' should be followed by a space", &s);
            message = true;
        }
        if (message) {
            tokenIndex_ = -4;
            ast::LevelSource entry;
            entry.isMessage = true;
            entry.message = toUtf8(js::trim(std::u16string_view(mixedCase).substr(std::min(s.pos(), mixedCase.size()))));
            entry.line = line_;
            if (!game_.levels.back().isMessage && game_.levels.back().rows.empty()) {
                game_.levels.insert(game_.levels.end() - 1, std::move(entry));
            } else {
                game_.levels.push_back(std::move(entry));
            }
            return true;
        }
        size_t n2 = matchUntilParen(s.rest());
        U16 row = js::trim(s.rest().substr(0, n2 == kNoMatch ? 0 : n2));
        tokenIndex_ = 2;
        ast::LevelSource& last = game_.levels.back();
        if (last.isMessage) {
            ast::LevelSource level;
            level.line = line_;
            level.rows.push_back(row);
            game_.levels.push_back(std::move(level));
        } else {
            if (last.rows.empty()) last.line = line_;
            last.rows.push_back(row);
            if (last.rows.size() > 1 && row.size() != last.rows.front().size()) {
                warning("level rows differ in length; levels must be rectangular", &s);
            }
        }
    } else if (tokenIndex_ == -4) {
        s.skipToEnd();
        return true;
    }
    if (tokenIndex_ == 2 && !s.eol()) {
        char16_t c = static_cast<char16_t>(s.peek());
        s.next();
        if (!glyphs_.count(std::u16string(1, c))) {
            error("the level glyph \"" + toUpperAscii(toUtf8(std::u16string(1, c))) +
                      "\" is not defined (add it to the legend)", &s);
        }
        return true;
    }
    return false;
}

// ---------------------------------------------------------------- prelude

bool Scanner::preludeToken(LineCursor& s, bool sol, const U16& mixedCase) {
    if (sol) tokenIndex_ = 0;
    if (tokenIndex_ != 0) {
        s.consume(matchUntilParen(s.rest()));
        ++tokenIndex_;
        if (tokenIndex_ > 2) warning("a prelude value cannot contain a comment; the text after it is ignored", &s);
        return true;
    }
    size_t n = s.consume(matchSingleWord(s.rest()));
    if (n == kNoMatch) {
        error("unexpected text \"" + toUtf8(s.text()) + "\" in the prelude", &s);
        return false;
    }
    if (!sol) return true;
    std::string key = toUtf8(js::trim(std::u16string_view(s.text()).substr(s.pos() - n, n)));
    if (kMetadataWithValue.count(key)) {
        if (key == "author" || key == "homepage" || key == "title") s.replaceText(mixedCase);
        if (key == "youtube") warning("YOUTUBE is no longer supported", &s);
        size_t m = matchUntilParen(s.rest());
        if (m != kNoMatch) {
            std::string value = toUtf8(js::trim(s.rest().substr(0, m)));
            if (game_.metadataLines.count(key)) {
                warning("prelude key " + toUpperAscii(key) + " was already given on line " +
                            std::to_string(game_.metadataLines[key]), &s);
            }
            game_.metadata.push_back(ast::MetadataEntry{key, value, line_});
            game_.metadataLines[key] = line_;
        } else {
            error("prelude key " + key + " needs a value", &s);
        }
        tokenIndex_ = 1;
        return true;
    }
    if (kMetadataFlags.count(key)) {
        game_.metadata.push_back(ast::MetadataEntry{key, "true", line_});
        tokenIndex_ = -1;
        size_t m = matchUntilParen(s.rest());
        if (m != kNoMatch) {
            warning("prelude flag " + toUpperAscii(key) + " takes no value, but was given \"" +
                        toUtf8(js::trim(s.rest().substr(0, m))) + "\"", &s);
        }
        return true;
    }
    error("unknown prelude key", &s);
    return true;
}

}  // namespace

bool isKeyword(const std::string& word) { return kKeywords.count(word) > 0; }
bool isCommandWord(const std::string& word) { return kCommandWords.count(word) > 0; }

ast::Game scanGame(std::string_view source, Diagnostics& diagnostics) {
    return Scanner(diagnostics).run(source);
}

}  // namespace psc::parse
