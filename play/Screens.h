// The player's screens other than the level itself: the title screen, the
// message screens (in the game's text and background colours, as the
// reference draws them), the level select, and the status and help lines.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "Canvas.h"
#include "LevelView.h"

namespace psc::play {

// Words of `text` in lines of at most `width` characters (longer words are cut).
std::vector<std::string> wrapText(const std::string& text, int width);

struct Theme {
    uint32_t background = 0x000000;
    uint32_t text = 0xffffff;
};

struct TitleScreen {
    std::string title;
    std::string author;
    std::string homepage;
    std::vector<std::string> choices;
    int selected = 0;
    std::string note;  // the game completed, or where progress lives
};

void drawTitle(Canvas& canvas, Area area, const TitleScreen& screen, const Theme& theme);
void drawMessage(Canvas& canvas, Area area, const std::string& message, const Theme& theme);

struct LevelSelectScreen {
    int levelCount = 0;
    std::set<int> solved;
    int cursor = 0;
};
// Returns how many levels one row of the grid holds (for moving up and down).
int drawLevelSelect(Canvas& canvas, Area area, const LevelSelectScreen& screen);

// A line in reverse video: `left` at the left, `right` at the right when both fit.
void drawBar(Canvas& canvas, int row, const std::string& left, const std::string& right);
// A plain line, cut to the canvas.
void drawLine(Canvas& canvas, int row, const std::string& text, bool bold = false);

}  // namespace psc::play
