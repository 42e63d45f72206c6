#include <catch2/catch.hpp>

#include "base/Diagnostics.h"

using namespace psc;

TEST_CASE("identical messages on one line are reported once", "[diagnostics]") {
    Diagnostics d;
    d.error(3, "x");
    d.error(3, "x");
    d.error(4, "x");
    CHECK(d.all().size() == 2);
    CHECK(d.errorCount() == 2);
}

TEST_CASE("a warning without a line counts as an error", "[diagnostics]") {
    Diagnostics d;
    d.warning(3, "w");
    CHECK(d.errorCount() == 0);
    d.warning(std::nullopt, "w");
    CHECK(d.errorCount() == 1);
}

TEST_CASE("more than 100 messages abort", "[diagnostics]") {
    Diagnostics d;
    for (int i = 0; i < 100; ++i) d.warning(i + 1, "w");
    CHECK_THROWS_AS(d.warning(200, "w"), CompileAborted);
}
