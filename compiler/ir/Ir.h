// psc's IR: a compiled PuzzleScript game, the input of every back end.
//
// It holds what the reference engine runs: objects with ids and collision
// layers, rule groups of concrete single-direction rules in execution order
// (each cell a set of object and movement masks), loop points, rigid groups,
// win conditions, levels as per-cell object sets, and the sound tables that
// can influence simulation.  Object sets are BitSets over object ids;
// movement sets are BitSets with 5 bits per collision layer (up, down, left,
// right, action), the reference's layout.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "base/BitSet.h"

namespace psc::ir {

// Direction bits, as in a layer's movement field.
enum Direction : int { kUp = 1, kDown = 2, kLeft = 4, kRight = 8, kAction = 16 };
const char* directionName(int direction);  // "up", "down", "left", "right", "action", or "?"

struct Object {
    int id = 0;
    std::string name;
    std::optional<int> layer;          // none for a ghost id
    bool ghost = false;                // an earlier collision-layer listing of an object listed twice
    std::optional<int> listedInLayer;  // ghosts: the layer of that listing
    std::optional<int> liveId;         // ghosts: the object's real id
    int line = 0;                      // declaration line
    std::vector<std::string> colors;   // "#rrggbb" or "transparent"
    std::vector<std::vector<int>> sprite;  // 5x5 palette indices, -1 = transparent
};

struct Replacement {
    BitSet clear;               // objects removed
    BitSet set;                 // objects added
    BitSet movementsClear;
    BitSet movementsSet;
    BitSet movementsLayerMask;  // whole layer fields also cleared (and rigid claims)
    BitSet randomEntity;        // `random X` candidates
    BitSet randomDirMask;       // movement-shaped; a layer's up bit marks `randomdir`
};

struct CellPattern {
    bool ellipsis = false;
    BitSet present;
    BitSet missing;
    std::vector<BitSet> anyOf;  // one per unexpanded single-layer property
    BitSet movementsPresent;
    BitSet movementsMissing;
    std::optional<Replacement> replacement;
};

struct Command {
    std::string name;
    std::string message;  // for `message`
    bool operator==(const Command&) const = default;
};

struct Rule {
    int line = 0;
    int groupNumber = 0;
    int direction = kDown;  // the direction the rule scans in
    bool late = false;
    bool rigid = false;
    bool random = false;
    bool hasReplacements = true;
    std::vector<Command> commands;
    std::vector<int> ellipsisCount;  // per row
    std::vector<std::vector<CellPattern>> rows;
};

struct RuleGroup {
    int groupNumber = 0;
    bool random = false;  // decided by the group's first rule
    std::vector<Rule> rules;
};

struct WinCondition {
    int quantifier = 0;  // -1 no, 0 some/any, +1 all
    BitSet objects;
    bool onEverything = false;  // no `on`: the second mask is all objects
    BitSet on;
    bool aggregate1 = false;
    bool aggregate2 = false;
    int line = 0;
};

struct Level {
    bool isMessage = false;
    std::string message;
    int width = 0;
    int height = 0;
    int line = 0;
    std::vector<BitSet> cells;  // column-major: cells[x * height + y]
};

struct MoveSound {
    int layer = 0;
    int objectId = 0;
    int directions = 0;  // direction bits
    std::string seed;
};

struct ObjectSound {
    BitSet objects;
    std::string seed;
};

struct Sounds {
    std::map<std::string, std::string> events;
    std::vector<ObjectSound> create;
    std::vector<ObjectSound> destroy;
    std::vector<std::vector<MoveSound>> move;  // per layer
    std::vector<MoveSound> cantMove;
};

struct Legend {
    std::map<std::string, std::string> synonyms;
    std::map<std::string, std::vector<std::string>> properties;
    std::map<std::string, std::vector<std::string>> aggregates;
    std::map<std::string, int> singleLayerProperties;
    std::map<std::string, std::vector<int>> glyphs;  // objects placed, in layer order
};

// A prelude value after the compiler's reading: text, or a WxH pair.
struct MetadataValue {
    std::string text;
    std::optional<std::pair<int, int>> size;  // flickscreen / zoomscreen
};

struct Background {
    int id = 0;
    int layer = 0;
};

struct Game {
    std::string title;
    int errorCount = 0;
    std::vector<std::pair<std::string, MetadataValue>> metadata;  // first-definition order, last value

    int objectCount = 0;  // ids, ghost ids included
    int layerCount = 0;
    std::vector<Object> objects;  // by id
    std::vector<std::string> unlayeredObjects;
    std::vector<BitSet> layerMasks;
    BitSet playerMask;
    bool playerIsAggregate = false;
    std::optional<Background> background;
    Legend legend;

    std::vector<RuleGroup> rules;
    std::vector<RuleGroup> lateRules;
    std::map<int, int> loopPoints;      // last group of a loop -> its first group
    std::map<int, int> lateLoopPoints;
    bool hasRigid = false;
    std::vector<bool> rigidGroups;
    std::vector<int> rigidGroupIndexToGroupIndex;
    std::map<int, int> groupIndexToRigidGroupIndex;
    std::map<int, int> groupNumberToRigidGroupIndex;

    std::vector<WinCondition> winConditions;
    std::vector<Level> levels;
    Sounds sounds;
    std::vector<std::string> notes;

    bool hasMetadata(const std::string& key) const;
    const MetadataValue* metadataValue(const std::string& key) const;
    // Indices into `levels` of the playable levels (message entries skipped).
    std::vector<int> playableLevels() const;
};

}  // namespace psc::ir
