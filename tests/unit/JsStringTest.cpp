#include <catch2/catch.hpp>

#include <cmath>

#include "base/JsString.h"

using namespace psc::js;

TEST_CASE("toLower follows String.prototype.toLowerCase", "[js]") {
    CHECK(toLower(std::string("PLAYER Wall_2")) == "player wall_2");
    // Dotted capital I lowers to two code units; a word-final sigma to ς.
    CHECK(toLower(fromUtf8("\xC4\xB0")) == fromUtf8("i\xCC\x87"));
    CHECK(toLower(std::string("\xCE\x9F\xCE\xA3")) == "\xCE\xBF\xCF\x82");
    CHECK(toLower(std::string("\xCE\xA3\xCE\x9F")) == "\xCF\x83\xCE\xBF");
}

TEST_CASE("UTF-8 decoding replaces malformed bytes", "[js]") {
    CHECK(fromUtf8("a\xFF" "b") == u"a\uFFFDb");
    CHECK(fromUtf8("\xF0\x9F\x98\x80").size() == 2);  // one astral code point, two code units
    CHECK(toUtf8(fromUtf8("caf\xC3\xA9")) == "caf\xC3\xA9");
    CHECK(lengthUtf16("\xF0\x9F\x98\x80") == 2);
}

TEST_CASE("regular-expression classes match JavaScript's", "[js]") {
    CHECK(isNameChar(U'a'));
    CHECK(isNameChar(U'_'));
    CHECK(isNameChar(U'\u00e9'));
    CHECK(isNameChar(U'\u0663'));  // Arabic-Indic digit
    CHECK_FALSE(isNameChar(U'#'));
    CHECK(isSpace(U'\u00a0'));
    CHECK(isSpace(U'\ufeff'));
    CHECK_FALSE(isSpace(U'x'));
    CHECK(isSeparator(U'\u3000'));
    CHECK_FALSE(isAsciiWordChar(U'\u00e9'));
}

TEST_CASE("object keys are listed in JavaScript order", "[js]") {
    CHECK(objectKeyOrder({"b", "10", "a", "2", "01"}) == std::vector<std::string>{"2", "10", "b", "a", "01"});
    CHECK(isArrayIndexKey("0"));
    CHECK_FALSE(isArrayIndexKey("4294967295"));
    CHECK_FALSE(isArrayIndexKey("-1"));
}

TEST_CASE("number conversions follow Number, parseFloat and parseInt", "[js]") {
    CHECK(toNumber(" 5 ") == 5);
    CHECK(toNumber("") == 0);
    CHECK(toNumber("0x10") == 16);
    CHECK(std::isnan(toNumber("5a")));
    CHECK(std::isinf(toNumber("Infinity")));
    CHECK(parseFloatJs("5.5x") == 5.5);
    CHECK(parseIntJs("1e1") == 1);
    CHECK(std::isnan(parseIntJs("x1")));
}

TEST_CASE("sorting compares UTF-16 code units", "[js]") {
    // U+FF21 sorts after U+1F600 in UTF-8 but before it in UTF-16.
    CHECK(lessUtf16("\xEF\xBC\xA1", "\xF0\x9F\x98\x80") == false);
    CHECK(lessUtf16("a", "b"));
}
