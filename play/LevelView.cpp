#include "LevelView.h"

#include <algorithm>
#include <map>

namespace psc::play {

GameDisplay makeGameDisplay(const ast::Game& ast, const ir::Game& game, const std::string& sourceText,
                            const psc_game_info& info) {
    GameDisplay d;
    d.glyphs = GlyphTable(ast, game, sourceText, info);
    d.playerChannel.assign(static_cast<size_t>(info.object_count), false);
    for (int c = 0; c < info.object_count; ++c) {
        for (const ir::Object& o : game.objects) {
            if (!o.ghost && o.name == info.object_names[c] && game.playerMask.test(static_cast<size_t>(o.id))) {
                d.playerChannel[static_cast<size_t>(c)] = true;
            }
        }
    }
    auto size = [&](const char* key) -> std::optional<std::pair<int, int>> {
        const ir::MetadataValue* v = game.metadataValue(key);
        if (!v || !v->size || v->size->first <= 0 || v->size->second <= 0) return std::nullopt;
        return v->size;
    };
    d.flickscreen = size("flickscreen");
    d.zoomscreen = size("zoomscreen");
    return d;
}

namespace {

constexpr int kSpriteSize = 5;

int spriteRows(int cells) { return (cells * kSpriteSize + 1) / 2; }

// Keeps [start, start + length) inside [0, total).
int clampStart(int start, int length, int total) { return std::max(0, std::min(start, total - length)); }

}  // namespace

LevelView::Window LevelView::window(const Session& session, int maxWidth, int maxHeight) {
    const int W = session.width(), H = session.height();
    for (int x = 0; x < W && !lastPlayer_; ++x) {
        for (int y = 0; y < H && !lastPlayer_; ++y) {
            for (int c = 0; c < info_.object_count; ++c) {
                if (display_.playerChannel[static_cast<size_t>(c)] && session.has(c, x, y)) {
                    lastPlayer_ = std::make_pair(x, y);
                    break;
                }
            }
        }
    }
    const auto [px, py] = lastPlayer_.value_or(std::make_pair(0, 0));
    Window w{0, 0, W, H};
    if (display_.flickscreen) {
        const auto [fw, fh] = *display_.flickscreen;
        w.x = px / fw * fw;
        w.y = py / fh * fh;
        w.width = std::min(fw, W - w.x);
        w.height = std::min(fh, H - w.y);
    } else if (display_.zoomscreen) {
        const auto [zw, zh] = *display_.zoomscreen;
        w.width = std::min(zw, W);
        w.height = std::min(zh, H);
        w.x = clampStart(px - zw / 2, w.width, W);
        w.y = clampStart(py - zh / 2, w.height, H);
    }
    // Larger than the terminal: the part around the player.
    if (w.width > maxWidth) {
        w.x = std::clamp(px - maxWidth / 2, w.x, w.x + w.width - maxWidth);
        w.width = std::max(maxWidth, 0);
    }
    if (w.height > maxHeight) {
        w.y = std::clamp(py - maxHeight / 2, w.y, w.y + w.height - maxHeight);
        w.height = std::max(maxHeight, 0);
    }
    return w;
}

LevelStyle LevelView::choose(const Session& session, Area area, bool forceGlyphs, ColorMode colors) {
    if (forceGlyphs || colors == ColorMode::None) return LevelStyle::Glyphs;
    lastPlayer_.reset();  // recomputed from the state shown
    const Window whole = window(session, session.width(), session.height());
    const bool fits = whole.width * kSpriteSize <= area.width && spriteRows(whole.height) <= area.height;
    return fits ? LevelStyle::Sprites : LevelStyle::Glyphs;
}

std::vector<int> LevelView::cellChannels(const Session& session, int x, int y) const {
    std::vector<int> channels;
    for (int c = 0; c < info_.object_count; ++c) {
        if (session.has(c, x, y)) channels.push_back(c);
    }
    return channels;
}

void LevelView::draw(Canvas& canvas, const Session& session, Area area, LevelStyle style, ColorMode colors) {
    lastPlayer_.reset();
    if (style == LevelStyle::Sprites) {
        drawSprites(canvas, session, area, window(session, area.width / kSpriteSize, area.height * 2 / kSpriteSize));
    } else {
        // One row under the level is kept for the key of its glyphs, when there is room.
        const int rows = area.height > session.height() ? area.height - 1 : area.height;
        drawGlyphs(canvas, session, area, window(session, area.width, rows), colors);
    }
}

void LevelView::drawSprites(Canvas& canvas, const Session& session, Area area, const Window& w) const {
    const int pixelWidth = w.width * kSpriteSize;
    const int pixelHeight = w.height * kSpriteSize;
    std::vector<uint32_t> pixels(static_cast<size_t>(pixelWidth) * pixelHeight, info_.background_color);
    for (int cx = 0; cx < w.width; ++cx) {
        for (int cy = 0; cy < w.height; ++cy) {
            for (int c : cellChannels(session, w.x + cx, w.y + cy)) {
                for (int p = 0; p < kSpriteSize * kSpriteSize; ++p) {
                    const int index = info_.object_sprites[c * 25 + p];
                    if (index < 0) continue;
                    const int px = cx * kSpriteSize + p % kSpriteSize;
                    const int py = cy * kSpriteSize + p / kSpriteSize;
                    pixels[static_cast<size_t>(py) * pixelWidth + px] = info_.object_colors[c * 10 + index];
                }
            }
        }
    }
    const int left = area.x + (area.width - pixelWidth) / 2;
    const int top = area.y + (area.height - spriteRows(w.height)) / 2;
    for (int row = 0; row < spriteRows(w.height); ++row) {
        for (int x = 0; x < pixelWidth; ++x) {
            const uint32_t upper = pixels[static_cast<size_t>(2 * row) * pixelWidth + x];
            Style s;
            s.fg = upper;
            if (2 * row + 1 < pixelHeight) {
                const uint32_t lower = pixels[static_cast<size_t>(2 * row + 1) * pixelWidth + x];
                s.bg = lower;
                if (lower == upper) {
                    canvas.put(left + x, top + row, " ", Style{std::nullopt, lower});
                    continue;
                }
            }
            canvas.put(left + x, top + row, "\u2580", s);  // upper half block
        }
    }
}

void LevelView::drawGlyphs(Canvas& canvas, const Session& session, Area area, const Window& w, ColorMode colors) const {
    const int left = area.x + (area.width - w.width) / 2;
    const int top = area.y + (area.height - w.height - 1) / 2;
    std::map<std::string, std::string> key;  // glyph -> what it shows
    for (int cy = 0; cy < w.height; ++cy) {
        for (int cx = 0; cx < w.width; ++cx) {
            const std::vector<int> channels = cellChannels(session, w.x + cx, w.y + cy);
            const std::string& glyph = display_.glyphs.glyph(channels);
            Style s;
            if (colors != ColorMode::None && !channels.empty()) {
                // The colour of the top object's first sprite pixel.
                const int c = channels.back();
                for (int p = 0; p < 25 && !s.fg; ++p) {
                    const int index = info_.object_sprites[c * 25 + p];
                    if (index >= 0) s.fg = info_.object_colors[c * 10 + index];
                }
            }
            canvas.put(left + cx, std::max(top, area.y) + cy, glyph, s);
            key.emplace(glyph, display_.glyphs.describe(channels));
        }
    }
    const int keyRow = std::max(top, area.y) + w.height + 1;
    if (keyRow >= area.y + area.height) return;
    std::string line;
    for (const auto& [glyph, what] : key) {
        if (glyph == " ") continue;
        line += (line.empty() ? "" : "  ") + glyph + " " + what;
    }
    const int width = static_cast<int>(characters(line).size());
    canvas.text(area.x + std::max(0, (area.width - width) / 2), keyRow, line, Style{}, area.width);
}

}  // namespace psc::play
