// ExpandDeadline: the clock of psc_set_deadline's deadlines on CPU batches.
// psc_expand passes its batch's deadline down to the engine, whose again loop
// reads this clock (templates/engine.h, deadlineClock), so that one input's
// long chain does not keep a search far past its time limit.
#pragma once

#include <stdint.h>

namespace psc_host {

// The steady clock, in nanoseconds.
int64_t steadyNanoseconds();

}  // namespace psc_host
