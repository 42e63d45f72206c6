#include "passes/CheckLayers.h"

#include <unordered_set>

namespace psc::passes {

void checkLayers(CompileState& st) {
    std::unordered_set<std::string> layered;
    for (const auto& layer : st.ast.collisionLayers) layered.insert(layer.begin(), layer.end());
    for (const std::string& name : st.objects.keys()) {
        if (!layered.count(name)) {
            st.diag.error(st.objects.at(name).line,
                          "object " + js::toUpperAscii(name) + " is defined but is in no collision layer");
        }
    }
}

}  // namespace psc::passes
