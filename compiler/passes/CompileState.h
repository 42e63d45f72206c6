// The state the compiler passes share while lowering an ast::Game to an
// ir::Game: the resolved legend tables, masks by name, and the rule list at
// each stage of expansion.  Each pass reads what earlier passes left here and
// writes its part of the IR.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ast/Ast.h"
#include "ir/Ir.h"
#include "base/BitSet.h"
#include "base/Diagnostics.h"
#include "base/JsObject.h"

namespace psc::passes {

struct ObjectInfo {
    std::optional<int> id;     // none when the object is in no collision layer
    std::optional<int> layer;
    int line = 0;
};

// A rule during expansion: one direction, rows of cells of (modifier, name)
// pairs, as the reference manipulates them.
struct WorkRule {
    std::string direction;
    std::vector<ast::RuleRow> lhs;
    std::vector<ast::RuleRow> rhs;
    int line = 0;
    int groupNumber = 0;
    bool late = false;
    bool rigid = false;
    bool random = false;
    std::vector<ast::RuleCommand> commands;

    // Set while encoding.
    std::optional<std::pair<std::string, std::string>> discard;  // two names that can never share a layer
    bool ellipsisAtEdge = false;
    std::string key;  // duplicate-removal key
};

// A rule after encoding: cells are masks.
struct EncodedRule {
    WorkRule source;
    std::vector<std::vector<ir::CellPattern>> rows;
};

// Legend member lists are shared when one name is defined as another (as in
// the reference, where both names then refer to the same array).
using Members = std::shared_ptr<std::vector<std::string>>;

struct CompileState {
    CompileState(ast::Game& game, Diagnostics& d, ir::Game& out) : ast(game), diag(d), ir(out) {}

    ast::Game& ast;
    Diagnostics& diag;
    ir::Game& ir;

    // generateExtraMembers
    JsObject<ObjectInfo> objects;  // every declared object, declaration order
    std::vector<std::string> idNames;  // id -> name (ghost ids included)
    JsObject<std::vector<int>> glyphs;  // name -> object id per layer, -1 for none
    JsObject<std::string> synonyms;
    JsObject<Members> properties;
    JsObject<Members> aggregates;
    JsObject<std::optional<int>> singleLayerProperties;  // present but empty: a member has no layer
    std::optional<int> backgroundId;
    std::optional<int> backgroundLayer;

    // generateMasks
    size_t objectBits = 0;
    BitSet playerMask;
    bool playerIsAggregate = false;
    std::vector<BitSet> layerMasks;
    JsObject<BitSet> objectMasks;
    JsObject<BitSet> aggregateMasks;

    // rule expansion
    std::vector<ast::RuleSyntax> ruleLines;  // rules read from the RULES section
    std::vector<std::pair<int, int>> loops;  // (line, +1 startloop / -1 endloop)
    std::vector<WorkRule> rules;
    std::vector<EncodedRule> encoded;
    std::vector<std::vector<EncodedRule>> groups;
    std::vector<std::vector<EncodedRule>> lateGroups;

    bool invalid = false;  // the reference would reject the game outright

    int layerCount() const { return static_cast<int>(ast.collisionLayers.size()); }
    const ObjectInfo* object(const std::string& name) const { return objects.find(name); }
    bool isProperty(const std::string& name) const { return properties.has(name); }
};

}  // namespace psc::passes
