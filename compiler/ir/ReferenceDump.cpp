#include "ir/ReferenceDump.h"

#include <algorithm>

#include "base/JsString.h"

namespace psc::ir {
namespace {

using json::Value;

const char* const kDirectionWords[5] = {"up", "down", "left", "right", "action"};

class Dumper {
public:
    explicit Dumper(const Game& g) : g_(g) {}

    Value run(const std::string& sha1);

private:
    std::string objectName(int id) const {
        if (id >= 0 && id < g_.objectCount && !g_.objects[static_cast<size_t>(id)].ghost) {
            return g_.objects[static_cast<size_t>(id)].name;
        }
        return "#" + std::to_string(id);
    }
    Value objects(const BitSet& mask) const {
        Value out = Value::array();
        mask.forEach([&](size_t id) { out.push(Value::string(objectName(static_cast<int>(id)))); });
        return out;
    }
    Value movements(const BitSet& mask) const {
        Value out = Value::object();
        std::vector<std::pair<int, Value>> fields;
        mask.forEach([&](size_t bit) {
            int layer = static_cast<int>(bit / 5);
            if (fields.empty() || fields.back().first != layer) fields.emplace_back(layer, Value::array());
            fields.back().second.push(Value::string(kDirectionWords[bit % 5]));
        });
        for (auto& [layer, dirs] : fields) out.set(std::to_string(layer), std::move(dirs));
        return out;
    }
    Value layersWithBits(const BitSet& mask) const {
        Value out = Value::array();
        int last = -1;
        mask.forEach([&](size_t bit) {
            int layer = static_cast<int>(bit / 5);
            if (layer != last) out.push(Value::integer(layer));
            last = layer;
        });
        return out;
    }
    static void setIfAny(Value& cell, const std::string& key, Value v) {
        if (!v.empty()) cell.set(key, std::move(v));
    }
    Value leftCell(const CellPattern& c) const;
    Value rightCell(const CellPattern& c) const;
    Value rule(const Rule& r) const;
    Value groups(const std::vector<RuleGroup>& groups) const;
    Value sounds() const;
    Value legend() const;

    const Game& g_;
};

Value Dumper::leftCell(const CellPattern& c) const {
    if (c.ellipsis) return std::move(Value::object().set("ellipsis", Value::boolean(true)).oneLine());
    Value cell = Value::object();
    setIfAny(cell, "present", objects(c.present));
    setIfAny(cell, "missing", objects(c.missing));
    Value anyOf = Value::array();
    for (const auto& m : c.anyOf) anyOf.push(objects(m));
    setIfAny(cell, "any_of", std::move(anyOf));
    setIfAny(cell, "moving", movements(c.movementsPresent));
    setIfAny(cell, "not_moving", movements(c.movementsMissing));
    return std::move(cell.oneLine());
}

Value Dumper::rightCell(const CellPattern& c) const {
    if (c.ellipsis) return std::move(Value::object().set("ellipsis", Value::boolean(true)).oneLine());
    if (!c.replacement) return Value::null();
    const Replacement& r = *c.replacement;
    // The clear mask as whole layers plus the objects left over.
    std::vector<int> ids = r.clear.bits();
    Value clearLayers = Value::array();
    for (size_t L = 0; L < g_.layerMasks.size(); ++L) {
        std::vector<int> layerIds = g_.layerMasks[L].bits();
        if (layerIds.empty()) continue;
        bool all = std::all_of(layerIds.begin(), layerIds.end(),
                               [&](int id) { return std::find(ids.begin(), ids.end(), id) != ids.end(); });
        if (!all) continue;
        clearLayers.push(Value::integer(static_cast<int64_t>(L)));
        for (int id : layerIds) ids.erase(std::find(ids.begin(), ids.end(), id));
    }
    Value clear = Value::array();
    for (int id : ids) clear.push(Value::string(objectName(id)));
    Value randomDir = Value::array();
    for (int L = 0; L < g_.layerCount; ++L) {
        if (r.randomDirMask.test(static_cast<size_t>(5 * L))) randomDir.push(Value::integer(L));
    }
    Value cell = Value::object();
    setIfAny(cell, "clear_layers", std::move(clearLayers));
    setIfAny(cell, "clear", std::move(clear));
    setIfAny(cell, "set", objects(r.set));
    setIfAny(cell, "movements_clear", movements(r.movementsClear));
    setIfAny(cell, "movements_set", movements(r.movementsSet));
    setIfAny(cell, "movements_layer_mask", layersWithBits(r.movementsLayerMask));
    setIfAny(cell, "random_entity", objects(r.randomEntity));
    setIfAny(cell, "random_dir_layers", std::move(randomDir));
    return std::move(cell.oneLine());
}

Value Dumper::rule(const Rule& r) const {
    Value commands = Value::array();
    for (const auto& c : r.commands) {
        Value cmd = Value::array().push(Value::string(c.name));
        if (c.name == "message") cmd.push(Value::string(c.message));
        commands.push(std::move(cmd));
    }
    Value ellipses = Value::array();
    for (int e : r.ellipsisCount) ellipses.push(Value::integer(e));
    Value lhs = Value::array();
    Value rhs = Value::array();
    for (const auto& row : r.rows) {
        Value left = Value::array();
        Value right = Value::array();
        for (const auto& cell : row) {
            left.push(leftCell(cell));
            right.push(rightCell(cell));
        }
        lhs.push(std::move(left));
        rhs.push(std::move(right));
    }
    Value out = Value::object();
    out.set("line", Value::integer(r.line));
    std::string direction = directionName(r.direction);
    if (direction == "?" || direction == std::string("action")) direction = "?" + std::to_string(r.direction);
    out.set("direction", Value::string(direction));
    out.set("late", Value::boolean(r.late));
    out.set("rigid", Value::boolean(r.rigid));
    out.set("random", Value::boolean(r.random));
    out.set("commands", std::move(commands));
    out.set("has_rhs", Value::boolean(r.hasReplacements));
    out.set("ellipsis_count", std::move(ellipses));
    out.set("lhs", std::move(lhs));
    out.set("rhs", r.hasReplacements ? std::move(rhs) : Value::null());
    return std::move(out.headerFields(8));
}

Value Dumper::groups(const std::vector<RuleGroup>& groups) const {
    Value out = Value::array();
    for (size_t i = 0; i < groups.size(); ++i) {
        Value rules = Value::array();
        for (const auto& r : groups[i].rules) rules.push(rule(r));
        Value group = Value::object();
        group.set("index", Value::integer(static_cast<int64_t>(i)));
        group.set("group_number", Value::integer(groups[i].groupNumber));
        group.set("random", Value::boolean(groups[i].random));
        group.set("rules", std::move(rules));
        out.push(std::move(group.headerFields(3)));
    }
    return out;
}

template <typename Map, typename F>
Value sortedMap(const Map& map, F f) {
    std::vector<std::string> keys;
    for (const auto& kv : map) keys.push_back(kv.first);
    std::sort(keys.begin(), keys.end(), js::lessUtf16);
    Value out = Value::object();
    for (const auto& k : keys) out.set(k, f(map.at(k)));
    return out;
}

Value stringList(const std::vector<std::string>& names) {
    Value out = Value::array();
    for (const auto& n : names) out.push(Value::string(n));
    return out;
}

Value Dumper::legend() const {
    Value out = Value::object();
    out.set("synonyms", sortedMap(g_.legend.synonyms, [](const std::string& v) { return Value::string(v); }));
    out.set("properties", sortedMap(g_.legend.properties, stringList));
    out.set("aggregates", sortedMap(g_.legend.aggregates, stringList));
    out.set("single_layer_properties", sortedMap(g_.legend.singleLayerProperties, [](int v) { return Value::integer(v); }));
    out.set("glyphs", sortedMap(g_.legend.glyphs, [&](const std::vector<int>& ids) {
        Value names = Value::array();
        for (int id : ids) names.push(Value::string(objectName(id)));
        return names;
    }));
    return out;
}

Value Dumper::sounds() const {
    auto moveSound = [&](const MoveSound& s) {
        Value dirs = Value::array();
        for (int k = 0; k < 5; ++k) {
            if ((s.directions >> k) & 1) dirs.push(Value::string(kDirectionWords[k]));
        }
        Value v = Value::object();
        v.set("layer", Value::integer(s.layer));
        v.set("objects", Value::array().push(Value::string(objectName(s.objectId))));
        v.set("directions", std::move(dirs));
        v.set("seed", Value::string(s.seed));
        return v;
    };
    auto objectSound = [&](const ObjectSound& s) {
        Value v = Value::object();
        v.set("objects", objects(s.objects));
        v.set("seed", Value::string(s.seed));
        return v;
    };
    Value out = Value::object();
    out.set("events", sortedMap(g_.sounds.events, [](const std::string& s) { return Value::string(s); }));
    Value create = Value::array();
    for (const auto& s : g_.sounds.create) create.push(objectSound(s));
    Value destroy = Value::array();
    for (const auto& s : g_.sounds.destroy) destroy.push(objectSound(s));
    Value move = Value::array();
    for (const auto& layer : g_.sounds.move) {
        Value list = Value::array();
        for (const auto& s : layer) list.push(moveSound(s));
        move.push(std::move(list));
    }
    Value cantMove = Value::array();
    for (const auto& s : g_.sounds.cantMove) cantMove.push(moveSound(s));
    out.set("create", std::move(create));
    out.set("destroy", std::move(destroy));
    out.set("move", std::move(move));
    out.set("cantmove", std::move(cantMove));
    return out;
}

Value Dumper::run(const std::string& sha1) {
    Value out = Value::object();
    out.set("source_sha1", Value::string(sha1));
    out.set("error_count", Value::integer(g_.errorCount));

    std::vector<std::string> keys;
    for (const auto& kv : g_.metadata) keys.push_back(kv.first);
    std::sort(keys.begin(), keys.end());
    Value metadata = Value::object();
    for (const auto& k : keys) {
        const MetadataValue& v = *g_.metadataValue(k);
        if (v.size) {
            metadata.set(k, Value::array().push(Value::integer(v.size->first)).push(Value::integer(v.size->second)));
        } else {
            metadata.set(k, Value::string(v.text));
        }
    }
    out.set("metadata", std::move(metadata));
    out.set("object_count", Value::integer(g_.objectCount));
    out.set("layer_count", Value::integer(g_.layerCount));

    Value objectList = Value::array();
    for (const Object& o : g_.objects) {
        Value v = Value::object();
        v.set("id", Value::integer(o.id));
        v.set("name", Value::string(o.name));
        if (!o.ghost) {
            v.set("layer", o.layer ? Value::integer(*o.layer) : Value::null());
        } else {
            v.set("layer", Value::null());
            v.set("ghost", Value::boolean(true));
            v.set("listed_in_layer", o.listedInLayer ? Value::integer(*o.listedInLayer) : Value::null());
            v.set("live_id", o.liveId ? Value::integer(*o.liveId) : Value::null());
        }
        objectList.push(std::move(v));
    }
    out.set("objects", std::move(objectList));
    out.set("unlayered_objects", stringList(g_.unlayeredObjects));
    Value layers = Value::array();
    for (const auto& m : g_.layerMasks) layers.push(objects(m));
    out.set("layers", std::move(layers));
    out.set("player", objects(g_.playerMask));
    out.set("player_is_aggregate", Value::boolean(g_.playerIsAggregate));
    if (g_.background) {
        Value bg = Value::object();
        bg.set("id", Value::integer(g_.background->id));
        bg.set("name", Value::string(objectName(g_.background->id)));
        bg.set("layer", Value::integer(g_.background->layer));
        out.set("background", std::move(bg));
    } else {
        out.set("background", Value::null());
    }
    out.set("legend", legend());
    out.set("rules", groups(g_.rules));
    out.set("late_rules", groups(g_.lateRules));
    auto intMap = [](const std::map<int, int>& m) {
        Value v = Value::object();
        for (const auto& [k, x] : m) v.set(std::to_string(k), Value::integer(x));
        return v;
    };
    out.set("loop_points", intMap(g_.loopPoints));
    out.set("late_loop_points", intMap(g_.lateLoopPoints));
    out.set("has_rigid", Value::boolean(g_.hasRigid));
    Value rigidGroups = Value::array();
    for (bool b : g_.rigidGroups) rigidGroups.push(Value::boolean(b));
    out.set("rigid_groups", std::move(rigidGroups));
    Value rigidToGroup = Value::array();
    for (int i : g_.rigidGroupIndexToGroupIndex) rigidToGroup.push(Value::integer(i));
    out.set("rigid_group_index_to_group_index", std::move(rigidToGroup));
    out.set("group_index_to_rigid_group_index", intMap(g_.groupIndexToRigidGroupIndex));
    out.set("group_number_to_rigid_group_index", intMap(g_.groupNumberToRigidGroupIndex));

    Value wins = Value::array();
    for (const auto& w : g_.winConditions) {
        Value v = Value::object();
        v.set("quantifier", Value::string(w.quantifier < 0 ? "no" : w.quantifier > 0 ? "all" : "some"));
        v.set("objects", objects(w.objects));
        v.set("on", w.onEverything ? Value::null() : objects(w.on));
        v.set("aggregate1", Value::boolean(w.aggregate1));
        v.set("aggregate2", Value::boolean(w.aggregate2));
        v.set("line", Value::integer(w.line));
        wins.push(std::move(v));
    }
    out.set("win_conditions", std::move(wins));

    Value entries = Value::array();
    for (const auto& l : g_.levels) {
        Value v = Value::object();
        if (l.isMessage) {
            v.set("kind", Value::string("message"));
            v.set("text", Value::string(l.message));
        } else {
            v.set("kind", Value::string("level"));
            v.set("width", Value::integer(l.width));
            v.set("height", Value::integer(l.height));
            v.set("line", Value::integer(l.line));
        }
        entries.push(std::move(v));
    }
    Value levels = Value::object();
    levels.set("count", Value::integer(static_cast<int64_t>(g_.levels.size())));
    levels.set("entries", std::move(entries));
    out.set("levels", std::move(levels));
    out.set("sounds", sounds());
    out.set("notes", stringList(g_.notes));
    return out;
}

}  // namespace

json::Value referenceDump(const Game& game, const std::string& sourceSha1) { return Dumper(game).run(sourceSha1); }

std::string referenceDumpText(const Game& game, const std::string& sourceSha1) {
    return referenceDump(game, sourceSha1).pretty() + "\n";
}

}  // namespace psc::ir
