#include "Screens.h"

#include <algorithm>
#include <sstream>

namespace psc::play {
namespace {

int width(const std::string& text) { return static_cast<int>(characters(text).size()); }

void centred(Canvas& canvas, Area area, int row, const std::string& text, const Style& style) {
    canvas.text(area.x + std::max(0, (area.width - width(text)) / 2), row, text, style, area.width);
}

}  // namespace

std::vector<std::string> wrapText(const std::string& text, int limit) {
    limit = std::max(limit, 1);
    std::vector<std::string> lines;
    std::istringstream words(text);
    std::string line;
    for (std::string word; words >> word;) {
        while (width(word) > limit) {
            if (!line.empty()) lines.push_back(line);
            line.clear();
            const auto cs = characters(word);
            std::string head;
            for (int i = 0; i < limit; ++i) head += cs[static_cast<size_t>(i)];
            lines.push_back(head);
            word = word.substr(head.size());
        }
        if (line.empty()) line = word;
        else if (width(line) + 1 + width(word) <= limit) line += " " + word;
        else {
            lines.push_back(line);
            line = word;
        }
    }
    if (!line.empty()) lines.push_back(line);
    return lines;
}

void drawTitle(Canvas& canvas, Area area, const TitleScreen& s, const Theme& theme) {
    const Style plain{theme.text, theme.background};
    Style bold = plain;
    bold.bold = true;
    canvas.fill(area.x, area.y, area.width, area.height, Style{std::nullopt, theme.background});
    std::vector<std::pair<std::string, Style>> lines;
    for (const auto& l : wrapText(s.title.empty() ? "(untitled)" : s.title, std::min(area.width - 2, 60))) lines.emplace_back(l, bold);
    if (!s.author.empty()) lines.emplace_back("by " + s.author, plain);
    if (!s.homepage.empty()) lines.emplace_back(s.homepage, plain);
    lines.emplace_back("", plain);
    for (size_t i = 0; i < s.choices.size(); ++i) {
        const bool chosen = static_cast<int>(i) == s.selected;
        Style st = plain;
        st.reverse = chosen;
        lines.emplace_back((chosen ? "> " : "  ") + s.choices[i] + (chosen ? " <" : "  "), st);
    }
    lines.emplace_back("", plain);
    lines.emplace_back("X or Enter to choose, arrows to select", plain);
    if (!s.note.empty()) {
        lines.emplace_back("", plain);
        for (const auto& l : wrapText(s.note, std::min(area.width - 2, 60))) lines.emplace_back(l, plain);
    }
    const int top = area.y + std::max(0, (area.height - static_cast<int>(lines.size())) / 2);
    for (size_t i = 0; i < lines.size(); ++i) centred(canvas, area, top + static_cast<int>(i), lines[i].first, lines[i].second);
}

void drawMessage(Canvas& canvas, Area area, const std::string& message, const Theme& theme) {
    const Style plain{theme.text, theme.background};
    canvas.fill(area.x, area.y, area.width, area.height, Style{std::nullopt, theme.background});
    std::vector<std::string> lines = wrapText(message, std::min(area.width - 2, 40));
    lines.emplace_back("");
    lines.emplace_back("X to continue");
    const int top = area.y + std::max(0, (area.height - static_cast<int>(lines.size())) / 2);
    for (size_t i = 0; i < lines.size(); ++i) centred(canvas, area, top + static_cast<int>(i), lines[i], plain);
}

int drawLevelSelect(Canvas& canvas, Area area, const LevelSelectScreen& s) {
    constexpr int kItemWidth = 7;
    const int perRow = std::max(1, std::min(10, (area.width - 2) / kItemWidth));
    const int rows = (s.levelCount + perRow - 1) / perRow;
    centred(canvas, area, area.y + 1, "Level select  (* solved)", Style{{}, {}, true});
    const int left = area.x + std::max(0, (area.width - perRow * kItemWidth) / 2);
    // Rows around the cursor when the grid is taller than the area.
    const int visibleRows = std::max(1, area.height - 5);
    const int firstRow = std::clamp(s.cursor / perRow - visibleRows / 2, 0, std::max(0, rows - visibleRows));
    for (int level = firstRow * perRow; level < s.levelCount && level / perRow < firstRow + visibleRows; ++level) {
        const int row = area.y + 3 + level / perRow - firstRow;
        const std::string label = std::to_string(level + 1) + (s.solved.count(level) ? "*" : " ");
        Style st;
        st.reverse = level == s.cursor;
        canvas.text(left + (level % perRow) * kItemWidth + (kItemWidth - 1 - width(label)), row, label, st);
    }
    centred(canvas, area, area.y + area.height - 1, "arrows move, X or Enter plays, Esc goes back", Style{});
    return perRow;
}

void drawBar(Canvas& canvas, int row, const std::string& left, const std::string& right) {
    Style bar;
    bar.reverse = true;
    canvas.fill(0, row, canvas.columns(), 1, bar);
    const int used = canvas.text(1, row, left, bar, canvas.columns() - 2);
    const int rightWidth = width(right);
    if (used + 3 + rightWidth <= canvas.columns() - 1) canvas.text(canvas.columns() - 1 - rightWidth, row, right, bar);
}

void drawLine(Canvas& canvas, int row, const std::string& text, bool bold) {
    Style s;
    s.bold = bold;
    canvas.text(1, row, text, s, canvas.columns() - 2);
}

}  // namespace psc::play
