#include "Glyphs.h"

#include <algorithm>
#include <cctype>
#include <set>
#include <sstream>

namespace psc::play {
namespace {

// The code point of a UTF-8 string of exactly one character; -1 otherwise.
long singleCodePoint(const std::string& s) {
    if (s.empty()) return -1;
    const unsigned char c = static_cast<unsigned char>(s[0]);
    const size_t length = c < 0x80 ? 1 : c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : c >= 0xC0 ? 2 : 0;
    if (length == 0 || s.size() != length) return -1;
    long cp = length == 1 ? c : c & (0x3F >> (length - 1));
    for (size_t i = 1; i < length; ++i) cp = (cp << 6) | (static_cast<unsigned char>(s[i]) & 0x3F);
    return cp;
}

// Printable and one column wide in any terminal (East Asian wide characters,
// emoji and controls are not).
bool drawable(long cp) { return cp > 0x20 && cp != 0x7f && !(cp >= 0x80 && cp < 0xa0) && cp < 0x1100; }

// The glyph as the source wrote it: the legend keeps names in lower case.
std::string sourceCase(const std::string& glyph, const ast::Game& ast, const std::vector<std::string>& lines) {
    if (glyph.size() != 1 || !std::isalpha(static_cast<unsigned char>(glyph[0]))) return glyph;
    auto at = ast.nameLines.find(glyph);
    if (at == ast.nameLines.end() || at->second < 1 || static_cast<size_t>(at->second) > lines.size()) return glyph;
    std::string line = lines[static_cast<size_t>(at->second - 1)];
    std::replace(line.begin(), line.end(), '=', ' ');
    std::istringstream words(line);
    for (std::string word; words >> word;) {
        if (word.size() == 1 && std::tolower(static_cast<unsigned char>(word[0])) == glyph[0]) return word;
    }
    return glyph;
}

}  // namespace

GlyphTable::GlyphTable(const ast::Game& ast, const ir::Game& game, const std::string& sourceText,
                       const psc_game_info& info) {
    std::map<std::string, int> channelOf;
    for (int c = 0; c < info.object_count; ++c) {
        channelNames_.emplace_back(info.object_names[c]);
        channelOf[info.object_names[c]] = c;
        backgroundChannel_.push_back(game.background && info.object_layers[c] == game.background->layer);
    }
    std::vector<std::string> lines;
    std::istringstream text(sourceText);
    for (std::string line; std::getline(text, line);) lines.push_back(line);
    // Glyphs the levels use are preferred over their synonyms.
    std::set<std::string> inLevels;
    for (const auto& level : ast.levels) {
        for (const auto& row : level.rows) {
            for (char16_t unit : row) {
                if (unit < 0x80) inLevels.insert(std::string(1, static_cast<char>(unit)));
            }
        }
    }
    struct Candidate {
        std::string name;   // as the legend keeps it (lower case)
        std::string shown;  // as the source wrote it
        std::vector<int> channels;
    };
    std::vector<Candidate> candidates;
    for (const auto& [name, ids] : game.legend.glyphs) {
        const long cp = singleCodePoint(name);
        if (!drawable(cp)) continue;
        std::vector<int> channels;
        bool known = true;
        for (int id : ids) {
            auto c = channelOf.find(game.objects[static_cast<size_t>(id)].name);
            if (c == channelOf.end()) known = false;
            else channels.push_back(c->second);
        }
        if (!known || channels.empty()) continue;
        std::sort(channels.begin(), channels.end());
        candidates.push_back({name, sourceCase(name, ast, lines), channels});
    }
    std::stable_sort(candidates.begin(), candidates.end(), [&](const Candidate& a, const Candidate& b) {
        return inLevels.count(a.name) > inLevels.count(b.name);
    });
    for (const Candidate& c : candidates) {
        exact_.emplace(c.channels, c.shown);
        foreground_.emplace(withoutBackground(c.channels), c.shown);
    }
}

std::vector<int> GlyphTable::withoutBackground(const std::vector<int>& channels) const {
    std::vector<int> out;
    for (int c : channels) {
        if (!backgroundChannel_[static_cast<size_t>(c)]) out.push_back(c);
    }
    return out;
}

std::string GlyphTable::generated(const std::vector<int>& channels) const {
    const std::vector<int> fg = withoutBackground(channels);
    const std::vector<int>& shown = fg.empty() ? channels : fg;
    if (shown.empty()) return " ";
    const int top = shown.back();  // the last channel drawn is on top
    auto alone = foreground_.find(std::vector<int>{top});
    if (alone != foreground_.end()) return alone->second;
    const std::string& name = channelNames_[static_cast<size_t>(top)];
    for (char c : name) {
        if (std::isalnum(static_cast<unsigned char>(c))) return std::string(1, static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
    }
    return "?";
}

const std::string& GlyphTable::glyph(const std::vector<int>& channels) const {
    auto cached = cache_.find(channels);
    if (cached != cache_.end()) return cached->second;
    std::string g;
    if (auto e = exact_.find(channels); e != exact_.end()) g = e->second;
    else if (auto f = foreground_.find(withoutBackground(channels)); f != foreground_.end()) g = f->second;
    else g = generated(channels);
    return cache_.emplace(channels, g).first->second;
}

std::string GlyphTable::describe(const std::vector<int>& channels) const {
    std::vector<int> fg = withoutBackground(channels);
    if (fg.empty()) fg = channels;
    std::string out;
    for (int c : fg) out += (out.empty() ? "" : "+") + channelNames_[static_cast<size_t>(c)];
    return out.empty() ? "empty" : out;
}

}  // namespace psc::play
