#include "GameMutator.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <vector>

extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t maxSize);

namespace psc::fuzz {
namespace {

const char* const kSections[] = {"OBJECTS", "LEGEND", "SOUNDS", "COLLISIONLAYERS", "RULES", "WINCONDITIONS", "LEVELS"};
const char* const kSnippets[] = {
    "late [ > Player | Crate ] -> [ > Player | > Crate ]",
    "[ moving Player ] -> [ stationary Player ] again",
    "rigid [ > Crate | Crate ] -> [ > Crate | > Crate ]",
    "random [ Player ] -> [ Player Crate ]",
    "startloop",
    "endloop",
    "[ action Player ] -> [ ] message hi",
    "[ Player | ... | Crate ] -> [ Player | ... | ]",
    "horizontal [ > Player | no Wall ] -> cancel",
    "All Target on Crate",
    "No Player",
    "Some Crate",
    "message hello",
    "Player and Crate = Wall",
    "Thing = Player or Crate",
    "run_rules_on_level_start",
    "again_interval 0.1",
    "realtime_interval 0.2",
    "(a comment",
    ")",
    "=======",
    "0123.",
    "#####",
    "..P*.",
    "sfx0 36772507",
    "Player move up 12345",
};

std::vector<std::string> splitLines(const std::string& s) {
    std::vector<std::string> lines;
    size_t begin = 0;
    while (begin < s.size()) {
        size_t end = s.find('\n', begin);
        if (end == std::string::npos) end = s.size();
        lines.push_back(s.substr(begin, end - begin));
        begin = end + 1;
    }
    return lines;
}

std::string joinLines(const std::vector<std::string>& lines) {
    std::string out;
    for (const auto& l : lines) out += l + "\n";
    return out;
}

bool isSectionHeader(const std::string& line) {
    std::string word;
    for (char c : line) {
        if (!std::isspace(static_cast<unsigned char>(c))) word += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    }
    return std::find(std::begin(kSections), std::end(kSections), word) != std::end(kSections);
}

// Sections as line ranges [first, last); the prelude is the first.
std::vector<std::pair<size_t, size_t>> sections(const std::vector<std::string>& lines) {
    std::vector<std::pair<size_t, size_t>> out{{0, 0}};
    for (size_t i = 0; i < lines.size(); ++i) {
        if (isSectionHeader(lines[i])) out.push_back({i, i});
        out.back().second = i + 1;
    }
    return out;
}

std::vector<std::string> words(const std::string& text) {
    std::vector<std::string> out;
    std::string w;
    for (char c : text) {
        if (std::isalnum(static_cast<unsigned char>(c)) || c == '_') {
            w += c;
        } else {
            if (w.size() > 1) out.push_back(w);
            w.clear();
        }
    }
    if (w.size() > 1) out.push_back(w);
    return out;
}

std::string replaceWord(const std::string& text, const std::string& from, const std::string& to) {
    std::string out;
    size_t i = 0;
    auto wordChar = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
    while (i < text.size()) {
        if (text.compare(i, from.size(), from) == 0 && (i == 0 || !wordChar(text[i - 1])) &&
            (i + from.size() >= text.size() || !wordChar(text[i + from.size()]))) {
            out += to;
            i += from.size();
        } else {
            out += text[i++];
        }
    }
    return out;
}

}  // namespace

std::string mutateGame(const std::string& game, std::mt19937& rng) {
    std::vector<std::string> lines = splitLines(game);
    auto pick = [&](size_t n) { return n == 0 ? size_t{0} : static_cast<size_t>(rng() % n); };
    switch (rng() % 8) {
        case 0:  // duplicate a line
            if (!lines.empty()) {
                const size_t i = pick(lines.size());
                lines.insert(lines.begin() + static_cast<long>(pick(lines.size() + 1)), lines[i]);
            }
            break;
        case 1:  // drop a line
            if (!lines.empty()) lines.erase(lines.begin() + static_cast<long>(pick(lines.size())));
            break;
        case 2:  // swap two lines
            if (lines.size() > 1) std::swap(lines[pick(lines.size())], lines[pick(lines.size())]);
            break;
        case 3: {  // swap two sections
            auto s = sections(lines);
            if (s.size() > 2) {
                size_t a = 1 + pick(s.size() - 1), b = 1 + pick(s.size() - 1);
                if (a > b) std::swap(a, b);
                if (a != b) {
                    std::vector<std::string> out(lines.begin(), lines.begin() + static_cast<long>(s[a].first));
                    out.insert(out.end(), lines.begin() + static_cast<long>(s[b].first), lines.begin() + static_cast<long>(s[b].second));
                    out.insert(out.end(), lines.begin() + static_cast<long>(s[a].second), lines.begin() + static_cast<long>(s[b].first));
                    out.insert(out.end(), lines.begin() + static_cast<long>(s[a].first), lines.begin() + static_cast<long>(s[a].second));
                    out.insert(out.end(), lines.begin() + static_cast<long>(s[b].second), lines.end());
                    lines = out;
                }
            }
            break;
        }
        case 4: {  // duplicate or drop a whole section
            auto s = sections(lines);
            const auto [first, last] = s[pick(s.size())];
            std::vector<std::string> section(lines.begin() + static_cast<long>(first), lines.begin() + static_cast<long>(last));
            if (rng() % 2) lines.erase(lines.begin() + static_cast<long>(first), lines.begin() + static_cast<long>(last));
            else lines.insert(lines.begin() + static_cast<long>(pick(lines.size() + 1)), section.begin(), section.end());
            break;
        }
        case 5: {  // rename a name everywhere, to another name of the game or a new one
            const auto names = words(game);
            if (!names.empty()) {
                const std::string from = names[pick(names.size())];
                const std::string to = rng() % 2 ? names[pick(names.size())] : from + std::to_string(rng() % 10);
                return replaceWord(game, from, to);
            }
            break;
        }
        case 6:  // insert a keyword line
            lines.insert(lines.begin() + static_cast<long>(pick(lines.size() + 1)), kSnippets[pick(std::size(kSnippets))]);
            break;
        default: {  // insert a section header
            lines.insert(lines.begin() + static_cast<long>(pick(lines.size() + 1)), kSections[pick(std::size(kSections))]);
            break;
        }
    }
    return joinLines(lines);
}

size_t mutateGameBytes(uint8_t* data, size_t size, size_t maxSize, unsigned seed) {
    std::mt19937 rng(seed);
    if (rng() % 2) return LLVMFuzzerMutate(data, size, maxSize);
    const std::string mutated = mutateGame(std::string(reinterpret_cast<const char*>(data), size), rng);
    if (mutated.size() > maxSize) return LLVMFuzzerMutate(data, size, maxSize);
    std::memcpy(data, mutated.data(), mutated.size());
    return mutated.size();
}

}  // namespace psc::fuzz
