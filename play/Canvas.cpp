#include "Canvas.h"

#include <cstdlib>
#include <string>

namespace psc::play {

ColorMode detectColorMode() {
    const char* noColor = std::getenv("NO_COLOR");
    if (noColor && *noColor) return ColorMode::None;
    const std::string term = std::getenv("TERM") ? std::getenv("TERM") : "";
    if (term.empty() || term == "dumb") return ColorMode::None;
    const std::string colorTerm = std::getenv("COLORTERM") ? std::getenv("COLORTERM") : "";
    if (colorTerm == "truecolor" || colorTerm == "24bit" || term.find("direct") != std::string::npos) {
        return ColorMode::TrueColor;
    }
    if (term.find("256color") != std::string::npos) return ColorMode::Palette256;
    return ColorMode::None;
}

std::vector<std::string_view> characters(std::string_view utf8) {
    std::vector<std::string_view> out;
    for (size_t i = 0; i < utf8.size();) {
        size_t n = 1;
        while (i + n < utf8.size() && (static_cast<unsigned char>(utf8[i + n]) & 0xC0) == 0x80) ++n;
        out.push_back(utf8.substr(i, n));
        i += n;
    }
    return out;
}

Canvas::Canvas(int columns, int rows)
    : columns_(std::max(columns, 0)), rows_(std::max(rows, 0)), cells_(static_cast<size_t>(columns_) * rows_) {}

void Canvas::put(int x, int y, std::string_view character, const Style& style) {
    if (x < 0 || y < 0 || x >= columns_ || y >= rows_) return;
    Cell& cell = cells_[static_cast<size_t>(y) * columns_ + x];
    cell.character.assign(character);
    // Text drawn over a filled area keeps the area's background.
    Style s = style;
    if (!s.bg) s.bg = cell.style.bg;
    cell.style = s;
}

int Canvas::text(int x, int y, std::string_view utf8, const Style& style, int maxColumns) {
    int used = 0;
    for (std::string_view c : characters(utf8)) {
        if (used >= maxColumns) break;
        put(x + used, y, c, style);
        ++used;
    }
    return used;
}

void Canvas::fill(int x, int y, int width, int height, const Style& style) {
    for (int row = y; row < y + height; ++row) {
        for (int column = x; column < x + width; ++column) {
            if (column < 0 || row < 0 || column >= columns_ || row >= rows_) continue;
            Cell& cell = cells_[static_cast<size_t>(row) * columns_ + column];
            cell.character = " ";
            cell.style = style;
        }
    }
}

namespace {

// The nearest colour of xterm's 6x6x6 cube or grey ramp.
int palette256(uint32_t rgb) {
    const int r = (rgb >> 16) & 255, g = (rgb >> 8) & 255, b = rgb & 255;
    auto level = [](int v) { return v < 48 ? 0 : v < 115 ? 1 : (v - 35) / 40; };
    auto value = [](int l) { return l == 0 ? 0 : 55 + 40 * l; };
    const int lr = level(r), lg = level(g), lb = level(b);
    const int cube = 16 + 36 * lr + 6 * lg + lb;
    const int cr = value(lr), cg = value(lg), cb = value(lb);
    const int grey = (r + g + b) / 3;
    const int greyLevel = grey > 238 ? 23 : grey < 8 ? 0 : (grey - 8) / 10;
    const int gv = 8 + 10 * greyLevel;
    auto distance = [&](int x, int y, int z) { return (r - x) * (r - x) + (g - y) * (g - y) + (b - z) * (b - z); };
    return distance(gv, gv, gv) < distance(cr, cg, cb) ? 232 + greyLevel : cube;
}

void appendColor(std::string& out, ColorMode mode, bool foreground, uint32_t rgb) {
    if (mode == ColorMode::TrueColor) {
        out += foreground ? ";38;2;" : ";48;2;";
        out += std::to_string((rgb >> 16) & 255) + ";" + std::to_string((rgb >> 8) & 255) + ";" + std::to_string(rgb & 255);
    } else {
        out += foreground ? ";38;5;" : ";48;5;";
        out += std::to_string(palette256(rgb));
    }
}

std::string sgr(const Style& s, ColorMode mode) {
    std::string out = "\x1b[0";
    if (s.bold) out += ";1";
    if (s.reverse) out += ";7";
    if (mode != ColorMode::None) {
        if (s.fg) appendColor(out, mode, true, *s.fg);
        if (s.bg) appendColor(out, mode, false, *s.bg);
    }
    return out + "m";
}

}  // namespace

std::string Canvas::ansi(ColorMode mode) const {
    std::string out = "\x1b[H";
    for (int y = 0; y < rows_; ++y) {
        out += "\x1b[" + std::to_string(y + 1) + ";1H";
        Style current;
        out += "\x1b[0m";
        for (int x = 0; x < columns_; ++x) {
            const Cell& cell = cells_[static_cast<size_t>(y) * columns_ + x];
            Style wanted = cell.style;
            if (mode == ColorMode::None) wanted.fg = wanted.bg = std::nullopt;
            if (!(wanted == current)) {
                out += sgr(wanted, mode);
                current = wanted;
            }
            out += cell.character;
        }
        out += "\x1b[0m";
    }
    return out;
}

std::vector<std::string> Canvas::plainRows() const {
    std::vector<std::string> out;
    for (int y = 0; y < rows_; ++y) {
        std::string row;
        for (int x = 0; x < columns_; ++x) row += cells_[static_cast<size_t>(y) * columns_ + x].character;
        while (!row.empty() && row.back() == ' ') row.pop_back();
        out.push_back(row);
    }
    return out;
}

}  // namespace psc::play
