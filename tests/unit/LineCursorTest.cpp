#include <catch2/catch.hpp>

#include "parse/LineCursor.h"

using namespace psc::parse;

TEST_CASE("names take letters, digits and underscores plus trailing space", "[cursor]") {
    CHECK(matchName(u"crate_2  rest") == 9);
    CHECK(matchName(u"#wall") == kNoMatch);
    CHECK(matchName(u"\u00e9t\u00e9 ") == 4);
}

TEST_CASE("colours match the first listed name, without a word boundary", "[cursor]") {
    std::string word;
    CHECK(matchColor(u"darkgray x", &word) == 9);
    CHECK(word == "darkgray");
    CHECK(matchColor(u"redd", &word) == 3);
    CHECK(word == "red");
    CHECK(matchColor(u"#12345", &word) == 4);
    CHECK(word == "#123");
    CHECK(matchColor(u"#a1b2c3", &word) == 7);
    CHECK(matchColor(u"ultraviolet", &word) == kNoMatch);
}

TEST_CASE("keyword alternations respect word boundaries", "[cursor]") {
    std::string word;
    CHECK(matchSoundEvent(u"sfx10 123", &word) == 6);
    CHECK(word == "sfx10");
    CHECK(matchSoundEvent(u"sfx1x", &word) == kNoMatch);
    CHECK(matchSectionName(u"levels", &word) == 6);
    CHECK(matchSectionName(u"levels2", &word) == kNoMatch);
    CHECK(matchSectionName(u"rules_x", &word) == kNoMatch);
    CHECK(matchSoundVerb(u"moved", &word) == kNoMatch);
    CHECK(matchSoundSeed(u"123abc") == kNoMatch);
    CHECK(matchSoundSeed(u"123 ") == 3);
}

TEST_CASE("small shapes", "[cursor]") {
    CHECK(matchLegendKey(u"@ = crate") == 1);
    CHECK(matchLegendKey(u"= crate") == 0);
    CHECK(matchRuleArrow(u"  -> [") == 5);
    CHECK(matchRulePart(u"player|") == 6);
    CHECK(isEqualsLine(u"=== ="));
    CHECK_FALSE(isEqualsLine(u"==.="));
    CHECK(matchMessageKeyword(u"message hi", true) == 8);
    CHECK(matchMessageKeyword(u"messagehi", true) == kNoMatch);
    CHECK(matchMessageKeyword(u"messagehi", false) == 7);
}
