#include "passes/BuildMasks.h"

#include <algorithm>

namespace psc::passes {
namespace {

void setObjectBit(const CompileState& st, BitSet& mask, const ObjectInfo* o) {
    if (!o || st.objectBits == 0) return;
    mask.set(static_cast<size_t>(o->id.value_or(0)));
}

BitSet playerMask(CompileState& st, bool* aggregate) {
    BitSet mask(st.objectBits);
    *aggregate = false;
    const std::string name = "player";
    setObjectBit(st, mask, st.object(name));
    if (const Members* parts = st.aggregates.find(name)) {
        *aggregate = true;
        for (const auto& m : **parts) setObjectBit(st, mask, st.object(m));
    }
    if (const Members* members = st.properties.find(name)) {
        for (const auto& m : **members) setObjectBit(st, mask, st.object(m));
    }
    if (const std::string* target = st.synonyms.find(name)) setObjectBit(st, mask, st.object(*target));
    if (mask.none()) st.diag.error(std::nullopt, "no object called PLAYER found in OBJECTS or LEGEND");
    return mask;
}

}  // namespace

void buildMasks(CompileState& st) {
    st.playerMask = playerMask(st, &st.playerIsAggregate);

    for (int layer = 0; layer < st.layerCount(); ++layer) {
        BitSet mask(st.objectBits);
        for (const std::string& name : st.idNames) {
            const ObjectInfo& o = st.objects.at(name);
            if (o.layer == layer) mask.set(static_cast<size_t>(*o.id));
        }
        st.layerMasks.push_back(mask);
    }

    for (const std::string& name : st.objects.keys()) {
        BitSet mask(st.objectBits);
        setObjectBit(st, mask, st.object(name));
        st.objectMasks.set(name, mask);
    }
    std::vector<const ast::LegendDecl*> ordered;
    for (const auto& s : st.ast.synonyms) ordered.push_back(&s);
    for (const auto& p : st.ast.properties) ordered.push_back(&p);
    std::stable_sort(ordered.begin(), ordered.end(),
                     [](const ast::LegendDecl* a, const ast::LegendDecl* b) { return a->line < b->line; });
    for (const ast::LegendDecl* d : ordered) {
        if (d->members.size() == 1) {
            // A synonym (or a one-member property): share the member's mask.
            if (const BitSet* m = st.objectMasks.find(d->members[0])) st.objectMasks.set(d->name, *m);
        } else {
            BitSet mask(st.objectBits);
            for (const auto& member : d->members) {
                if (const BitSet* m = st.objectMasks.find(member)) mask |= *m;
            }
            st.objectMasks.set(d->name, mask);
        }
    }

    for (const std::string& name : st.aggregates.keys()) {
        BitSet mask(st.objectBits);
        for (const auto& part : *st.aggregates.at(name)) {
            if (const BitSet* m = st.objectMasks.find(part)) mask |= *m;
        }
        st.aggregateMasks.set(name, mask);
    }

    st.ir.playerMask = st.playerMask;
    st.ir.playerIsAggregate = st.playerIsAggregate;
    st.ir.layerMasks = st.layerMasks;
}

}  // namespace psc::passes
