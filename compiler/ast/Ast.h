// psc's abstract syntax tree: a PuzzleScript game as written, section by
// section, before any name is resolved.  Names are lower case (the language
// is case-insensitive); text that keeps its case (title, author, homepage,
// message text) is stored as written.  Lines are 1-based source lines.
//
// Rule lines are kept as text here and parsed into RuleSyntax by the rule
// grammar (grammar/PuzzleScript.g4) when the compiler reaches them, which is
// also when the reference compiler reads them.
#pragma once

#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

namespace psc::ast {

struct MetadataEntry {
    std::string key;
    std::string value;  // "true" for flags that take no value
    int line = 0;
};

struct ObjectDecl {
    std::string name;
    int line = 0;
    std::vector<std::string> colors;       // as written (lower case), unresolved
    std::vector<std::string> spriteRows;   // rows of '.' and digits, as written
};

// A legend line (or an alias on an object's name line, which is a synonym).
struct LegendDecl {
    enum class Kind { Synonym, Aggregate, Property };
    Kind kind = Kind::Synonym;
    std::string name;
    std::vector<std::string> members;  // a synonym has one; aggregates and properties are flattened
    int line = 0;
};

struct SoundWord {
    enum class Kind { Event, Name, Verb, Direction, Seed };
    Kind kind;
    std::string text;
};

struct SoundDecl {
    std::vector<SoundWord> words;
    int line = 0;
};

// One line of the RULES section, as the reference stores it: the text
// before the first comment (lower case), its line, and the line as written
// (for `message` text).
struct RuleLineSource {
    std::u16string text;
    std::u16string original;
    int line = 0;
};

// A rule line as the rule grammar reads it (the reference's intermediate
// rule): the directions it applies in, and rows of cells on each side.  A
// cell is a list of (modifier, name) pairs; the modifier is "" for a bare
// name, and an ellipsis is the pair ("...", "...").
struct RuleCellItem {
    std::string modifier;
    std::string name;
    bool operator==(const RuleCellItem&) const = default;
};
using RuleCell = std::vector<RuleCellItem>;
using RuleRow = std::vector<RuleCell>;

struct RuleCommand {
    std::string name;     // cancel, again, win, restart, checkpoint, sfx0..sfx10, message
    std::string message;  // the text of a message command
    bool operator==(const RuleCommand&) const = default;
};

struct RuleSyntax {
    enum class Kind { Rule, StartLoop, EndLoop };
    Kind kind = Kind::Rule;
    int line = 0;
    int groupNumber = 0;  // line of the first rule of its '+' group
    bool late = false;
    bool rigid = false;
    bool random = false;
    std::vector<std::string> directions;  // up, down, left, right (action after a `moving` prefix)
    std::vector<RuleRow> lhs;
    std::vector<RuleRow> rhs;
    std::vector<RuleCommand> commands;
};

struct WinConditionSource {
    std::vector<std::string> words;
    int line = 0;
};

// A LEVELS entry: a message, or a level given as rows of glyphs (each row a
// string of UTF-16 code units, trimmed, lower case).
struct LevelSource {
    bool isMessage = false;
    std::string message;
    int line = 0;
    std::vector<std::u16string> rows;
};

struct Game {
    std::vector<MetadataEntry> metadata;                  // in source order, repeats kept
    std::unordered_map<std::string, int> metadataLines;   // key -> line of its last definition

    std::vector<ObjectDecl> objects;                      // declaration order
    std::unordered_map<std::string, size_t> objectIndex;  // name -> index into objects

    std::vector<LegendDecl> synonyms;
    std::vector<LegendDecl> aggregates;
    std::vector<LegendDecl> properties;

    std::vector<SoundDecl> sounds;
    std::vector<std::vector<std::string>> collisionLayers;  // names, properties expanded
    std::vector<RuleLineSource> rules;
    std::vector<WinConditionSource> winConditions;
    std::vector<LevelSource> levels;                      // may contain empty placeholders

    // The names rules and win conditions may use: everything declared before
    // the SOUNDS heading (the reference fixes this set there).
    std::set<std::string> ruleNames;

    // The line that most recently declared each name (object, alias or legend entry).
    std::unordered_map<std::string, int> nameLines;

    const ObjectDecl* findObject(const std::string& name) const {
        auto it = objectIndex.find(name);
        return it == objectIndex.end() ? nullptr : &objects[it->second];
    }
};

}  // namespace psc::ast
