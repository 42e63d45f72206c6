// SHA-1 of a byte string, as lowercase hex (the corpus names game sources by it).
#pragma once

#include <string>
#include <string_view>

namespace psc {

std::string sha1Hex(std::string_view data);

}  // namespace psc
