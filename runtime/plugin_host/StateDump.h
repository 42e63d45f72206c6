// The canonical state dump (psc_dump_state): the JSON the corpus' traces
// record of the reference engine's state after each input.
#pragma once

#include <string>

namespace psc_host {

std::string dumpState(const void* env);

}  // namespace psc_host
