#include "passes/MarkSpawnedStationary.h"

#include <algorithm>

namespace psc::passes {

void markSpawnedStationary(CompileState& st) {
    for (WorkRule& rule : st.rules) {
        if (rule.late) continue;
        for (size_t j = 0; j < rule.rhs.size(); ++j) {
            for (size_t k = 0; k < rule.rhs[j].size(); ++k) {
                std::vector<std::string> leftObjects;
                for (const auto& item : rule.lhs[j][k]) {
                    if (st.objects.has(item.name)) {
                        leftObjects.push_back(item.name);
                    } else if (const Members* members = st.properties.find(item.name)) {
                        leftObjects.insert(leftObjects.end(), (*members)->begin(), (*members)->end());
                    }
                }
                std::vector<std::optional<int>> leftLayers;
                for (const auto& name : leftObjects) {
                    if (const ObjectInfo* o = st.object(name)) leftLayers.push_back(o->layer);
                }
                for (auto& item : rule.rhs[j][k]) {
                    if (!item.modifier.empty()) continue;
                    if (st.properties.has(item.name)) continue;
                    if (std::find(leftObjects.begin(), leftObjects.end(), item.name) != leftObjects.end()) continue;
                    const ObjectInfo* o = st.object(item.name);
                    if (!o) continue;
                    if (std::find(leftLayers.begin(), leftLayers.end(), o->layer) == leftLayers.end()) {
                        item.modifier = "stationary";
                    }
                }
            }
        }
    }
}

}  // namespace psc::passes
