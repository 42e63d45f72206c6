// JavaScript string semantics for the front end.
//
// The reference engine reads a game as JavaScript strings: UTF-16 code units,
// lower-cased with String.prototype.toLowerCase, matched by regular
// expressions whose classes (\s, \p{L}, \p{N}, \p{Z}) are Unicode-aware.
// Level glyphs are single UTF-16 code units.  To read every game exactly as
// the reference does, the scanner works on std::u16string with the helpers
// below; names leave the front end as UTF-8 std::string.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace psc::js {

using U16 = std::u16string;

// UTF-8 → UTF-16; malformed bytes become U+FFFD, as a browser's decoder does.
U16 fromUtf8(std::string_view utf8);
// UTF-16 → UTF-8; lone surrogates become U+FFFD.
std::string toUtf8(std::u16string_view utf16);

// String.prototype.toLowerCase (full mappings, including final sigma).
U16 toLower(std::u16string_view s);
std::string toLower(std::string_view utf8);
// ASCII-only upper case, used for names inside diagnostics.
std::string toUpperAscii(std::string_view s);

// Unicode classes as JavaScript regular expressions see them.
bool isLetter(char32_t cp);     // \p{L}
bool isNumber(char32_t cp);     // \p{N}
bool isSeparator(char32_t cp);  // \p{Z}
bool isSpace(char32_t cp);      // \s (also String.prototype.trim's set)
bool isCased(char32_t cp);
inline bool isSpaceOrSeparator(char32_t cp) { return isSpace(cp) || isSeparator(cp); }
inline bool isNameChar(char32_t cp) { return isLetter(cp) || isNumber(cp) || cp == U'_'; }
// \w without the u+i flags: ASCII letters, digits and underscore.
inline bool isAsciiWordChar(char32_t cp) {
    return (cp >= U'a' && cp <= U'z') || (cp >= U'A' && cp <= U'Z') || (cp >= U'0' && cp <= U'9') || cp == U'_';
}

// The code point starting at s[i] (a surrogate pair counts as one); `units`
// receives how many code units it spans.
char32_t codePointAt(std::u16string_view s, size_t i, size_t* units);

// String.prototype.trim.
U16 trim(std::u16string_view s);
std::string trim(std::string_view utf8);

// Length in UTF-16 code units (String.prototype.length).
size_t lengthUtf16(std::string_view utf8);

// The JavaScript decimal rendering of an integer-valued double is plain; this
// tells whether a property key is an "array index" (JavaScript orders such
// keys numerically before all other keys of an object).
bool isArrayIndexKey(std::string_view key);

// Keys in the order Object.keys() would list them for an object whose keys
// were inserted in the given order.
std::vector<std::string> objectKeyOrder(const std::vector<std::string>& insertionOrder);

// Compare like Array.prototype.sort's default comparator (UTF-16 code units).
bool lessUtf16(std::string_view a, std::string_view b);

// Number(s) for the forms prelude values use (decimal, exponent, hex,
// Infinity, surrounding whitespace); NaN when JavaScript would give NaN.
double toNumber(std::string_view s);
// parseFloat(s) and parseInt(s, 10).
double parseFloatJs(std::string_view s);
double parseIntJs(std::string_view s);

}  // namespace psc::js
