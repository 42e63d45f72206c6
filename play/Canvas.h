// A frame of terminal cells, written out as ANSI text in one go: 24-bit or
// 256 colours, or none.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace psc::play {

enum class ColorMode { None, Palette256, TrueColor };

// The colours a terminal announces ($COLORTERM, $TERM, $NO_COLOR).
ColorMode detectColorMode();

struct Style {
    std::optional<uint32_t> fg;  // 0xRRGGBB; none: the terminal's own
    std::optional<uint32_t> bg;
    bool bold = false;
    bool reverse = false;
    bool operator==(const Style&) const = default;
};

class Canvas {
public:
    Canvas(int columns, int rows);
    int columns() const { return columns_; }
    int rows() const { return rows_; }

    // One character of width 1 (UTF-8); outside the canvas: nothing.
    void put(int x, int y, std::string_view character, const Style& style);
    // Text from column x, one column per character, cut at maxColumns; returns the columns used.
    int text(int x, int y, std::string_view utf8, const Style& style, int maxColumns = 1 << 30);
    // Paints the background of a rectangle.
    void fill(int x, int y, int width, int height, const Style& style);

    // The whole frame, from the top left corner, lines ended by clearing to their end.
    std::string ansi(ColorMode mode) const;
    // The characters alone, trailing spaces removed.
    std::vector<std::string> plainRows() const;

private:
    struct Cell {
        std::string character = " ";
        Style style;
    };
    int columns_;
    int rows_;
    std::vector<Cell> cells_;
};

// Splits UTF-8 text into characters (code points).
std::vector<std::string_view> characters(std::string_view utf8);

}  // namespace psc::play
