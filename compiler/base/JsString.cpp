#include "base/JsString.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace psc::js {
namespace {

struct CodePointRange {
    char32_t first;
    char32_t last;
};

struct LowerCaseMapping {
    char32_t from;
    uint8_t length;
    char16_t to[3];
};

#include "base/UnicodeTables.inc"

template <size_t N>
bool inRanges(const CodePointRange (&ranges)[N], char32_t cp) {
    auto it = std::upper_bound(std::begin(ranges), std::end(ranges), cp,
                               [](char32_t c, const CodePointRange& r) { return c < r.first; });
    if (it == std::begin(ranges)) return false;
    --it;
    return cp <= it->last;
}

const LowerCaseMapping* lowerMapping(char32_t cp) {
    auto it = std::lower_bound(std::begin(kLowerCase), std::end(kLowerCase), cp,
                               [](const LowerCaseMapping& m, char32_t c) { return m.from < c; });
    if (it == std::end(kLowerCase) || it->from != cp) return nullptr;
    return &*it;
}

void appendUtf16(U16& out, char32_t cp) {
    if (cp < 0x10000) {
        out.push_back(static_cast<char16_t>(cp));
    } else {
        cp -= 0x10000;
        out.push_back(static_cast<char16_t>(0xD800 + (cp >> 10)));
        out.push_back(static_cast<char16_t>(0xDC00 + (cp & 0x3FF)));
    }
}

void appendUtf8(std::string& out, char32_t cp) {
    if (cp < 0x80) {
        out.push_back(static_cast<char>(cp));
    } else if (cp < 0x800) {
        out.push_back(static_cast<char>(0xC0 | (cp >> 6)));
        out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
    } else if (cp < 0x10000) {
        out.push_back(static_cast<char>(0xE0 | (cp >> 12)));
        out.push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3F)));
        out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
    } else {
        out.push_back(static_cast<char>(0xF0 | (cp >> 18)));
        out.push_back(static_cast<char>(0x80 | ((cp >> 12) & 0x3F)));
        out.push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3F)));
        out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
    }
}

bool isSurrogate(char32_t cp) { return cp >= 0xD800 && cp <= 0xDFFF; }

}  // namespace

U16 fromUtf8(std::string_view in) {
    U16 out;
    out.reserve(in.size());
    size_t i = 0;
    while (i < in.size()) {
        const auto b0 = static_cast<unsigned char>(in[i]);
        char32_t cp = 0xFFFD;
        size_t len = 1;
        auto cont = [&](size_t k) {
            return i + k < in.size() && (static_cast<unsigned char>(in[i + k]) & 0xC0) == 0x80;
        };
        if (b0 < 0x80) {
            cp = b0;
        } else if (b0 >= 0xC2 && b0 < 0xE0 && cont(1)) {
            cp = ((b0 & 0x1F) << 6) | (in[i + 1] & 0x3F);
            len = 2;
        } else if (b0 >= 0xE0 && b0 < 0xF0 && cont(1) && cont(2)) {
            char32_t c = ((b0 & 0x0F) << 12) | ((in[i + 1] & 0x3F) << 6) | (in[i + 2] & 0x3F);
            if (c >= 0x800 && !isSurrogate(c)) {
                cp = c;
                len = 3;
            }
        } else if (b0 >= 0xF0 && b0 < 0xF5 && cont(1) && cont(2) && cont(3)) {
            char32_t c = ((b0 & 0x07) << 18) | ((in[i + 1] & 0x3F) << 12) | ((in[i + 2] & 0x3F) << 6) |
                         (in[i + 3] & 0x3F);
            if (c >= 0x10000 && c <= 0x10FFFF) {
                cp = c;
                len = 4;
            }
        }
        appendUtf16(out, cp);
        i += len;
    }
    return out;
}

std::string toUtf8(std::u16string_view s) {
    std::string out;
    out.reserve(s.size());
    for (size_t i = 0; i < s.size();) {
        size_t units = 1;
        char32_t cp = codePointAt(s, i, &units);
        appendUtf8(out, isSurrogate(cp) ? 0xFFFD : cp);
        i += units;
    }
    return out;
}

char32_t codePointAt(std::u16string_view s, size_t i, size_t* units) {
    char16_t c = s[i];
    if (c >= 0xD800 && c <= 0xDBFF && i + 1 < s.size() && s[i + 1] >= 0xDC00 && s[i + 1] <= 0xDFFF) {
        *units = 2;
        return 0x10000 + ((static_cast<char32_t>(c) - 0xD800) << 10) + (s[i + 1] - 0xDC00);
    }
    *units = 1;
    return c;
}

bool isLetter(char32_t cp) { return inRanges(kLetterRanges, cp); }
bool isNumber(char32_t cp) { return inRanges(kNumberRanges, cp); }
bool isSeparator(char32_t cp) { return inRanges(kSeparatorRanges, cp); }
bool isCased(char32_t cp) { return inRanges(kCasedRanges, cp); }

bool isSpace(char32_t cp) {
    switch (cp) {
        case 0x09: case 0x0A: case 0x0B: case 0x0C: case 0x0D: case 0x20: case 0xA0: case 0x1680:
        case 0x2028: case 0x2029: case 0x202F: case 0x205F: case 0x3000: case 0xFEFF:
            return true;
        default:
            return cp >= 0x2000 && cp <= 0x200A;
    }
}

U16 toLower(std::u16string_view s) {
    U16 out;
    out.reserve(s.size());
    for (size_t i = 0; i < s.size();) {
        size_t units = 1;
        char32_t cp = codePointAt(s, i, &units);
        if (cp == 0x3A3) {
            // Final sigma: a capital sigma that ends a word lowers to ς.
            bool casedBefore = false;
            if (i > 0) {
                size_t j = i - 1;
                if (j > 0 && s[j] >= 0xDC00 && s[j] <= 0xDFFF) --j;
                size_t u = 1;
                casedBefore = isCased(codePointAt(s, j, &u));
            }
            bool casedAfter = false;
            if (i + units < s.size()) {
                size_t u = 1;
                casedAfter = isCased(codePointAt(s, i + units, &u));
            }
            out.push_back((casedBefore && !casedAfter) ? u'\u03C2' : u'\u03C3');
        } else if (const LowerCaseMapping* m = lowerMapping(cp)) {
            out.append(m->to, m->length);
        } else {
            out.append(s.substr(i, units));
        }
        i += units;
    }
    return out;
}

std::string toLower(std::string_view utf8) { return toUtf8(toLower(fromUtf8(utf8))); }

std::string toUpperAscii(std::string_view s) {
    std::string out(s);
    for (char& c : out) {
        if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
    }
    return out;
}

U16 trim(std::u16string_view s) {
    size_t b = 0;
    size_t e = s.size();
    while (b < e && isSpace(s[b])) ++b;
    while (e > b && isSpace(s[e - 1])) --e;
    return U16(s.substr(b, e - b));
}

std::string trim(std::string_view utf8) { return toUtf8(trim(fromUtf8(utf8))); }

size_t lengthUtf16(std::string_view utf8) { return fromUtf8(utf8).size(); }

bool isArrayIndexKey(std::string_view key) {
    if (key.empty() || key.size() > 10) return false;
    if (key.size() > 1 && key[0] == '0') return false;
    uint64_t v = 0;
    for (char c : key) {
        if (c < '0' || c > '9') return false;
        v = v * 10 + static_cast<uint64_t>(c - '0');
    }
    return v < 0xFFFFFFFFull;
}

std::vector<std::string> objectKeyOrder(const std::vector<std::string>& insertionOrder) {
    std::vector<std::string> indices;
    std::vector<std::string> others;
    for (const auto& k : insertionOrder) (isArrayIndexKey(k) ? indices : others).push_back(k);
    std::sort(indices.begin(), indices.end(), [](const std::string& a, const std::string& b) {
        return a.size() != b.size() ? a.size() < b.size() : a < b;
    });
    indices.insert(indices.end(), others.begin(), others.end());
    return indices;
}

bool lessUtf16(std::string_view a, std::string_view b) { return fromUtf8(a) < fromUtf8(b); }

namespace {

std::string_view trimAscii(std::string_view s) {
    U16 t = trim(fromUtf8(s));
    // Values reaching here are ASCII in practice; keep non-ASCII text so it fails to parse.
    static thread_local std::string buffer;
    buffer = toUtf8(t);
    return buffer;
}

// Longest prefix of s that is a StrDecimalLiteral; returns its length.
size_t decimalPrefix(std::string_view s, bool allowInfinity) {
    size_t i = 0;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    if (allowInfinity && s.substr(i, 8) == "Infinity") return i + 8;
    size_t digits = 0;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i, ++digits;
    if (i < s.size() && s[i] == '.') {
        size_t j = i + 1;
        size_t frac = 0;
        while (j < s.size() && s[j] >= '0' && s[j] <= '9') ++j, ++frac;
        if (digits + frac > 0) {
            i = j;
            digits += frac;
        }
    }
    if (digits == 0) return 0;
    if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
        size_t j = i + 1;
        if (j < s.size() && (s[j] == '+' || s[j] == '-')) ++j;
        size_t expDigits = 0;
        while (j < s.size() && s[j] >= '0' && s[j] <= '9') ++j, ++expDigits;
        if (expDigits > 0) i = j;
    }
    return i;
}

double parseDecimal(std::string_view s) {
    if (s.find("Infinity") != std::string_view::npos) {
        return s[0] == '-' ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
    }
    return std::strtod(std::string(s).c_str(), nullptr);
}

}  // namespace

double toNumber(std::string_view raw) {
    std::string s(trimAscii(raw));
    if (s.empty()) return 0.0;
    if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X' || s[1] == 'o' || s[1] == 'O' ||
                                        s[1] == 'b' || s[1] == 'B')) {
        int base = (s[1] == 'x' || s[1] == 'X') ? 16 : (s[1] == 'o' || s[1] == 'O') ? 8 : 2;
        double v = 0;
        for (size_t i = 2; i < s.size(); ++i) {
            char c = s[i];
            int d = (c >= '0' && c <= '9') ? c - '0' : (c >= 'a' && c <= 'f') ? c - 'a' + 10
                  : (c >= 'A' && c <= 'F') ? c - 'A' + 10 : 99;
            if (d >= base) return std::nan("");
            v = v * base + d;
        }
        return v;
    }
    size_t n = decimalPrefix(s, true);
    if (n != s.size()) return std::nan("");
    return parseDecimal(s);
}

double parseFloatJs(std::string_view raw) {
    std::string s(trimAscii(raw));
    size_t n = decimalPrefix(s, true);
    if (n == 0) return std::nan("");
    return parseDecimal(s.substr(0, n));
}

double parseIntJs(std::string_view raw) {
    std::string s(trimAscii(raw));
    size_t i = 0;
    bool negative = false;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) negative = s[i++] == '-';
    size_t start = i;
    double v = 0;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9') v = v * 10 + (s[i++] - '0');
    if (i == start) return std::nan("");
    return negative ? -v : v;
}

}  // namespace psc::js
