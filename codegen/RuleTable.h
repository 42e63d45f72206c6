// RuleTable: emits a game's rules in the compact form, as data.
//
// Straight-line rule code (RuleCode) grows with every expanded rule, and the
// largest corpus games expand to tens of thousands of rules: tens of
// megabytes of C++ that no compiler finishes within minutes.  In this form
// each rule is a record of one table (kRuleData) that a fixed interpreter
// (templates/rule_table.h) walks, and so are the groups, their order, rigid
// bans and loops: the code does not grow with the game.  Both forms do the
// same things in the same order, so a game steps bit for bit alike in
// either; this one is slower per rule and compiles in seconds.
#pragma once

#include <cstddef>
#include <string>

#include "CodeWriter.h"
#include "ir/Ir.h"

namespace psc::codegen {

// kTableMaxRows, kTableMaxSavedCells, kLayerObjectStart, kLayerObjects,
// kRuleData, kRuleIndex, kEarlyGroups and kLateGroups (the groups, their
// rigid bans and loops): what templates/rule_table.h reads.
void emitRuleTableData(CodeWriter& out, const ir::Game& game);

// applyEarlyRules and applyLateRules over the table.
void emitRuleTableGroups(CodeWriter& out);

// Above this much straight-line rule code (RuleCode's text), `auto` picks the
// table: on the 2-core development machine a CPU plugin at -O2 takes about
// 100 s of one core per megabyte of it (Spooki, 0.36 MB: 24 s; Witch Lifter,
// 0.35 MB: 31 s; Two Worlds, 0.60 MB: 60 s with --rules code), the bar for
// any game is 60 s, and a CUDA plugin of 0.35 MB takes 36-37 s.  As a table,
// the largest game (55 MB of rule code) builds in 18 s (CPU) and 23 s (CUDA).
// Tables step 1.7-3x slower on one CPU thread, 0.9-1x as fast on the GPU's
// memory layout (docs/robustness.md, docs/performance.md).
constexpr size_t kTableRuleCodeBytes = 400'000;

}  // namespace psc::codegen
