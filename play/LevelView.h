// Drawing a level: its sprites in 24-bit (or 256) colour with half-block
// characters, a 5x5 sprite in 5 columns and 2.5 rows, when the terminal has
// colour and room for them; otherwise one glyph per cell, with a key of the
// glyphs below.  The camera follows the game's flickscreen and zoomscreen,
// and keeps the player in view when the level is larger than the terminal.
#pragma once

#include <optional>
#include <utility>
#include <vector>

#include "Canvas.h"
#include "Glyphs.h"
#include "Session.h"

namespace psc::play {

// What the player needs from the compiled game besides its plugin.
struct GameDisplay {
    GlyphTable glyphs;
    std::vector<bool> playerChannel;                      // by observation channel
    std::optional<std::pair<int, int>> flickscreen;       // cells shown, screen by screen
    std::optional<std::pair<int, int>> zoomscreen;        // cells shown, around the player
};
GameDisplay makeGameDisplay(const ast::Game& ast, const ir::Game& game, const std::string& sourceText,
                            const psc_game_info& info);

struct Area {
    int x = 0, y = 0, width = 0, height = 0;
};

enum class LevelStyle { Sprites, Glyphs };

class LevelView {
public:
    LevelView(const GameDisplay& display, const psc_game_info& info) : display_(display), info_(info) {}

    // Sprites when colours are on, glyphs are not forced and the view fits.
    LevelStyle choose(const Session& session, Area area, bool forceGlyphs, ColorMode colors);
    void draw(Canvas& canvas, const Session& session, Area area, LevelStyle style, ColorMode colors);
    // A new level: the camera forgets where the player was.
    void resetCamera() { lastPlayer_.reset(); }

private:
    struct Window {
        int x = 0, y = 0, width = 0, height = 0;
    };
    // The cells shown when at most maxWidth x maxHeight fit.
    Window window(const Session& session, int maxWidth, int maxHeight);
    std::vector<int> cellChannels(const Session& session, int x, int y) const;
    void drawSprites(Canvas& canvas, const Session& session, Area area, const Window& w) const;
    void drawGlyphs(Canvas& canvas, const Session& session, Area area, const Window& w, ColorMode colors) const;

    const GameDisplay& display_;
    const psc_game_info& info_;
    std::optional<std::pair<int, int>> lastPlayer_;
};

}  // namespace psc::play
