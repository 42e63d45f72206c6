#include "passes/ReadMetadata.h"

#include <cmath>

#include "base/Palettes.h"

namespace psc::passes {
namespace {

// One side of WxH, read as the reference does (JavaScript number rules).
double readDimension(CompileState& st, const std::string& text, int line) {
    double number = js::toNumber(text);
    double asFloat = js::parseFloatJs(text);
    bool isInteger = !std::isnan(number) && static_cast<double>(static_cast<int32_t>(asFloat)) == asFloat;
    if (!std::isfinite(number) || !isInteger) {
        st.diag.warning(line, "\"" + text + "\" is not a whole number");
        return std::nan("");
    }
    double value = js::parseIntJs(text);
    if (std::isnan(value)) st.diag.warning(line, "\"" + text + "\" is not a number");
    if (value <= 0) st.diag.warning(line, "dimension \"" + text + "\" must be greater than 0");
    return value;
}

std::optional<std::pair<int, int>> readSize(CompileState& st, const std::string& value, int line) {
    std::vector<std::string> parts;
    size_t start = 0;
    while (true) {
        size_t x = value.find('x', start);
        parts.push_back(value.substr(start, x == std::string::npos ? std::string::npos : x - start));
        if (x == std::string::npos) break;
        start = x + 1;
    }
    if (parts.size() != 2) {
        st.diag.warning(line, "dimensions are written WxH");
        return std::nullopt;
    }
    double w = readDimension(st, parts[0], line);
    double h = readDimension(st, parts[1], line);
    if (!std::isfinite(js::toNumber(parts[0])) || !std::isfinite(js::toNumber(parts[1])) || std::isnan(w) ||
        std::isnan(h)) {
        st.diag.warning(line, "cannot read the dimensions \"" + value + "\"; write them as WxH");
        return std::nullopt;
    }
    if (w <= 0 || h <= 0) st.diag.warning(line, "the dimensions \"" + value + "\" must be greater than 0");
    return std::make_pair(static_cast<int>(w), static_cast<int>(h));
}

}  // namespace

void readMetadata(CompileState& st) {
    auto& out = st.ir.metadata;
    for (const auto& entry : st.ast.metadata) {
        auto it = std::find_if(out.begin(), out.end(), [&](const auto& kv) { return kv.first == entry.key; });
        if (it == out.end()) out.emplace_back(entry.key, ir::MetadataValue{entry.value, std::nullopt});
        else it->second = ir::MetadataValue{entry.value, std::nullopt};
    }
    for (const char* key : {"flickscreen", "zoomscreen"}) {
        auto it = std::find_if(out.begin(), out.end(), [&](const auto& kv) { return kv.first == key; });
        if (it == out.end()) continue;
        int line = st.ast.metadataLines.count(key) ? st.ast.metadataLines.at(key) : 0;
        auto size = readSize(st, it->second.text, line);
        if (size) it->second.size = size;
        else out.erase(it);
    }

    std::string palette = palette::kDefaultPalette;
    for (const auto& m : st.ast.metadata) {
        if (m.key == "color_palette") {
            if (auto p = palette::resolve(m.value)) palette = *p;
        }
    }
    auto checkColor = [&](const char* key, const char* what) {
        const ir::MetadataValue* v = st.ir.metadataValue(key);
        if (!v) return;
        std::string hex = palette::toHex(palette, v->text);
        if (!palette::isColor(hex)) {
            std::optional<int> line;
            if (st.ast.metadataLines.count(key)) line = st.ast.metadataLines.at(key);
            st.diag.error(line, std::string(what) + " \"" + hex + "\" is not a colour name or #rrggbb");
        }
    };
    checkColor("text_color", "text_color");
    checkColor("background_color", "background_color");
    if (const ir::MetadataValue* title = st.ir.metadataValue("title")) st.ir.title = title->text;
    // The homepage is kept without its scheme (the first "http://", then the first "https://").
    for (auto& [key, value] : out) {
        if (key != "homepage") continue;
        for (const std::string scheme : {"http://", "https://"}) {
            if (size_t at = value.text.find(scheme); at != std::string::npos) value.text.erase(at, scheme.size());
        }
    }
}

}  // namespace psc::passes
