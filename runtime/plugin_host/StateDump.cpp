#include "StateDump.h"

#include <algorithm>
#include <vector>

#include "Batch.h"

namespace psc_host {
namespace {

void appendJsonString(std::string& out, const char* s) {
    static const char* hex = "0123456789abcdef";
    out += '"';
    for (const unsigned char* p = reinterpret_cast<const unsigned char*>(s); *p; ++p) {
        switch (*p) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\r': out += "\\r"; break;
            case '\t': out += "\\t"; break;
            case '\b': out += "\\b"; break;
            case '\f': out += "\\f"; break;
            default:
                if (*p < 0x20) {
                    out += "\\u00";
                    out += hex[*p >> 4];
                    out += hex[*p & 15];
                } else {
                    out += static_cast<char>(*p);
                }
        }
    }
    out += '"';
}

constexpr int kScreenMessage = 1;
constexpr int kScreenTitle = 2;

}  // namespace

std::string dumpState(const void* env) {
    const GameModule& g = game();
    EnvView v;
    g.view(env, &v);
    std::string out = "{\"level\":" + std::to_string(v.entry) + ",\"screen\":";
    out += v.screen == kScreenTitle ? "\"title\"" : v.screen == kScreenMessage ? "\"message\"" : "\"level\"";
    out += ",\"message\":";
    if (v.screen == kScreenTitle) {
        out += "\"#title\"";
    } else if (v.screen == kScreenMessage) {
        appendJsonString(out, v.entry >= 0 && v.entry < g.info->entry_count ? g.info->entry_messages[v.entry] : "");
    } else {
        out += "null";
    }
    out += ",\"won\":";
    out += (v.screen == kScreenTitle && v.startExisted) ? "true" : "false";
    out += ",\"width\":" + std::to_string(v.width) + ",\"height\":" + std::to_string(v.height);
    std::vector<std::string> palette;
    std::string rows = "[";
    std::vector<int> ids(static_cast<size_t>(g.objectCount));
    for (int y = 0; y < v.height; ++y) {
        rows += y ? ",[" : "[";
        for (int x = 0; x < v.width; ++x) {
            const int n = g.cellObjects(env, x, y, ids.data());
            std::sort(ids.begin(), ids.begin() + n, [&](int a, int b) { return g.objectNameRank[a] < g.objectNameRank[b]; });
            std::string cell;
            for (int k = 0; k < n; ++k) {
                if (k) cell += ' ';
                cell += g.objectNames[ids[static_cast<size_t>(k)]];
            }
            size_t index = std::find(palette.begin(), palette.end(), cell) - palette.begin();
            if (index == palette.size()) palette.push_back(cell);
            rows += (x ? "," : "") + std::to_string(index);
        }
        rows += "]";
    }
    rows += "]";
    out += ",\"palette\":[";
    for (size_t i = 0; i < palette.size(); ++i) {
        if (i) out += ",";
        appendJsonString(out, palette[i].c_str());
    }
    out += "],\"rows\":" + rows + "}";
    return out;
}

}  // namespace psc_host
