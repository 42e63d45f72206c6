// RuleTable: emits a game's rules in the compact form, as data.
//
// Straight-line rule code (RuleCode) grows with every expanded rule, and the
// largest corpus games expand to tens of thousands of rules: tens of
// megabytes of C++ that no compiler finishes within minutes.  In this form
// each rule is a record of one table (kRuleData) that a fixed interpreter
// (templates/rule_table.h) walks; the groups' functions and the turn's call
// sequence stay code.  Both forms do the same things in the same order, so a
// game steps bit for bit alike in either; this one is slower per rule and
// compiles in seconds.
#pragma once

#include <cstddef>
#include <string>

#include "CodeWriter.h"
#include "ir/Ir.h"

namespace psc::codegen {

// kTableMaxRows, kTableMaxSavedCells, kLayerObjectStart, kLayerObjects,
// kRuleData and kRuleIndex: what templates/rule_table.h reads.
void emitRuleTableData(CodeWriter& out, const ir::Game& game);

// The groups' functions over the table, and applyEarlyRules/applyLateRules.
void emitRuleTableGroups(CodeWriter& out, const ir::Game& game);

// Above this much straight-line rule code (RuleCode's text), `auto` picks the
// table: the system compiler takes about 40 s of one core per megabyte of it.
constexpr size_t kTableRuleCodeBytes = 1'500'000;

}  // namespace psc::codegen
