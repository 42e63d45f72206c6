#include "ir/Ir.h"

namespace psc::ir {

const char* directionName(int direction) {
    switch (direction) {
        case kUp: return "up";
        case kDown: return "down";
        case kLeft: return "left";
        case kRight: return "right";
        case kAction: return "action";
        default: return "?";
    }
}

bool Game::hasMetadata(const std::string& key) const { return metadataValue(key) != nullptr; }

const MetadataValue* Game::metadataValue(const std::string& key) const {
    for (const auto& [k, v] : metadata) {
        if (k == key) return &v;
    }
    return nullptr;
}

std::vector<int> Game::playableLevels() const {
    std::vector<int> out;
    for (size_t i = 0; i < levels.size(); ++i) {
        if (!levels[i].isMessage) out.push_back(static_cast<int>(i));
    }
    return out;
}

}  // namespace psc::ir
