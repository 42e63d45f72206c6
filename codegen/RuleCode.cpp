#include "RuleCode.h"

#include <fmt/format.h>

#include <algorithm>
#include <functional>
#include <set>

#include "DirectionVariants.h"
#include "Identifiers.h"
#include "RuleParts.h"
#include "DormantGroups.h"
#include "SinglePassGroups.h"
#include "ir/IrDump.h"

namespace psc::codegen {
namespace {

using ir::CellPattern;
using ir::Game;
using ir::Rule;

// ---- cell patterns as board expressions and position tests

std::string objectBoard(int id) { return fmt::format("e.obj[{}]", id); }
std::string movementBoard(size_t bit) { return fmt::format("e.mov[{}]", bit); }

std::string joinWith(const std::vector<std::string>& items, const std::string& sep) {
    std::string out;
    for (size_t i = 0; i < items.size(); ++i) out += (i ? sep : "") + items[i];
    return out;
}

struct PatternTerms {
    std::vector<std::string> required;  // boards that must all hold (each may be an OR)
    std::vector<std::string> excluded;  // boards that must not hold
};

PatternTerms termsOf(const CellPattern& c) {
    PatternTerms t;
    c.present.forEach([&](size_t id) { t.required.push_back(objectBoard(static_cast<int>(id))); });
    for (const auto& any : c.anyOf) {
        std::vector<std::string> ors;
        any.forEach([&](size_t id) { ors.push_back(objectBoard(static_cast<int>(id))); });
        t.required.push_back(ors.empty() ? "Board::zero()" : ors.size() == 1 ? ors[0] : "(" + joinWith(ors, " | ") + ")");
    }
    c.movementsPresent.forEach([&](size_t bit) { t.required.push_back(movementBoard(bit)); });
    c.missing.forEach([&](size_t id) { t.excluded.push_back(objectBoard(static_cast<int>(id))); });
    c.movementsMissing.forEach([&](size_t bit) { t.excluded.push_back(movementBoard(bit)); });
    return t;
}

// The board of positions where the cell pattern holds.
std::string patternBoard(const CellPattern& c) {
    PatternTerms t = termsOf(c);
    std::string positive = t.required.empty() ? "e.inside" : joinWith(t.required, " & ");
    if (t.required.size() > 1) positive = "(" + positive + ")";
    if (t.excluded.empty()) return positive;
    return "andNot(" + positive + ", " + (t.excluded.size() == 1 ? t.excluded[0] : "(" + joinWith(t.excluded, " | ") + ")") + ")";
}

// Whether the cell pattern holds at position `pos` of the current board.
std::string patternAt(const CellPattern& c, const std::string& pos) {
    std::vector<std::string> tests;
    PatternTerms t = termsOf(c);
    if (t.required.empty()) tests.push_back("e.inside.test(" + pos + ")");
    for (const auto& r : t.required) tests.push_back(r + ".test(" + pos + ")");
    for (const auto& x : t.excluded) tests.push_back("!" + x + ".test(" + pos + ")");
    return joinWith(tests, " && ");
}

// ---- rows

bool isVertical(int direction) { return direction == ir::kUp || direction == ir::kDown; }

std::string stepExpr(int direction) {
    switch (direction) {
        case ir::kDown: return "1";
        case ir::kUp: return "-1";
        case ir::kRight: return "columnOf(e)";
        case ir::kLeft: return "-columnOf(e)";
        default: return "0";
    }
}

std::string offset(const std::string& base, const std::string& terms) {
    return terms.empty() ? base : base + " + d * (" + terms + ")";
}

// Where the cells of a row sit, given the row's start and gaps.
struct RowLayout {
    int index = 0;
    const std::vector<CellPattern>* cells = nullptr;
    std::vector<size_t> ellipses;  // cell indices of the ellipses (0, 1 or 2)

    std::string start() const { return fmt::format("s{}", index); }
    std::string gap(int which) const { return fmt::format("k{}{}", index, which == 0 ? "a" : "b"); }
    // Position of cell i (not an ellipsis).
    std::string position(size_t i) const {
        if (ellipses.empty() || i < ellipses[0]) return offset(start(), i == 0 ? "" : std::to_string(i));
        if (ellipses.size() == 1 || i < ellipses[1]) return offset(start(), gap(0) + " + " + std::to_string(i - 1));
        return offset(start(), gap(0) + " + " + gap(1) + " + " + std::to_string(i - 2));
    }
    size_t nonEllipsisCount() const { return cells->size() - ellipses.size(); }
};

RowLayout layoutOf(const Rule& rule, size_t r) {
    RowLayout row;
    row.index = static_cast<int>(r);
    row.cells = &rule.rows[r];
    for (size_t i = 0; i < rule.rows[r].size(); ++i) {
        if (rule.rows[r][i].ellipsis) row.ellipses.push_back(i);
    }
    return row;
}

// Emits the boards each row needs, computed before anything is applied:
// rowN (positions where the cells before the first ellipsis match) and, for
// rows with ellipses, rowN_cI for each later cell.
// `prefix` goes before the boards' names and the step's (`d`); where
// `guard` (a condition) is false, the row's board is empty.
void emitRowBoards(CodeWriter& out, const RowLayout& row, const std::string& prefix = "", const std::string& guard = "") {
    const auto& cells = *row.cells;
    const size_t prefixEnd = row.ellipses.empty() ? cells.size() : row.ellipses[0];
    std::vector<std::string> terms;
    for (size_t i = 0; i < prefixEnd; ++i) {
        std::string b = patternBoard(cells[i]);
        terms.push_back(i == 0 ? b : fmt::format("shiftBySteps<{}>({}, {} * {}d)", i, b, i, prefix));
    }
    const std::string board = joinWith(terms, " & ");
    out.line(fmt::format("const Board {}row{} = {};", prefix, row.index,
                         guard.empty() ? board : fmt::format("{} ? {} : Board::zero()", guard, board)));
    for (size_t i = prefixEnd; i < cells.size(); ++i) {
        if (cells[i].ellipsis) continue;
        out.line(fmt::format("const Board {}row{}_c{} = {};", prefix, row.index, i, patternBoard(cells[i])));
    }
}

std::string gapLimit(int direction, const RowLayout& row) {
    const int len = static_cast<int>(row.nonEllipsisCount());
    const std::string x = fmt::format("(s{} / columnOf(e))", row.index);
    const std::string y = fmt::format("(s{} % columnOf(e))", row.index);
    switch (direction) {
        case ir::kDown: return fmt::format("heightOf(e) - ({} + {}) + 1", y, len);
        case ir::kUp: return fmt::format("{} - {} + 2", y, len);
        case ir::kRight: return fmt::format("widthOf(e) - ({} + {}) + 1", x, len);
        default: return fmt::format("{} - {} + 2", x, len);
    }
}

// Tests of the cells from `first` to `last` (exclusive) against the row's saved boards.
std::string savedCellTests(const RowLayout& row, size_t first, size_t last) {
    std::vector<std::string> tests;
    for (size_t i = first; i < last; ++i) {
        if ((*row.cells)[i].ellipsis) continue;
        tests.push_back(fmt::format("row{}_c{}.test({})", row.index, i, row.position(i)));
    }
    return joinWith(tests, " && ");
}

// Emits the loops over one row's matches in scan order; `body` emits what
// happens for each (the next row's loops, or the action).
template <typename Body>
void emitRowLoops(CodeWriter& out, const Rule& rule, const RowLayout& row, Body body) {
    out.open(isVertical(rule.direction) ? fmt::format("PSC_FOR_VERTICAL(row{0}, s{0})", row.index)
                                        : fmt::format("PSC_FOR_HORIZONTAL(e, row{0}, s{0})", row.index));
    if (!row.ellipses.empty()) {
        const auto& cells = *row.cells;
        out.line(fmt::format("const int kmax{} = {};", row.index, gapLimit(rule.direction, row)));
        const size_t secondEnd = row.ellipses.size() == 2 ? row.ellipses[1] : cells.size();
        out.open(fmt::format("for (int {0} = 0; {0} < kmax{1}; ++{0})", row.gap(0), row.index));
        std::string middle = savedCellTests(row, row.ellipses[0] + 1, secondEnd);
        if (!middle.empty()) out.line("if (!(" + middle + ")) continue;");
        if (row.ellipses.size() == 2) {
            out.open(fmt::format("for (int {0} = 0; {1} + {0} < kmax{2} && {0} < kmax{2}; ++{0})", row.gap(1), row.gap(0),
                                 row.index));
            std::string last = savedCellTests(row, row.ellipses[1] + 1, cells.size());
            if (!last.empty()) out.line("if (!(" + last + ")) continue;");
            body();
            out.close();
        } else {
            body();
        }
        out.close();
    } else {
        body();
    }
    out.close();
}

// Whether row r still matches at its start (and gaps) on the current board.
std::string recheck(const RowLayout& row) {
    std::vector<std::string> tests;
    for (size_t i = 0; i < row.cells->size(); ++i) {
        const CellPattern& c = (*row.cells)[i];
        if (c.ellipsis) continue;
        tests.push_back("(" + patternAt(c, row.position(i)) + ")");
    }
    return joinWith(tests, " && ");
}

// ---- replacements

void emitObjectUpdates(CodeWriter& out, const std::vector<ObjectUpdate>& updates) {
    for (const ObjectUpdate& u : updates) {
        if (u.kind == ObjectUpdate::kPutLayer) {
            out.line(fmt::format("ch |= putLayer{}(e, p, {});", u.layerOrObject, u.keepOrValue));
        } else {
            out.line(fmt::format("ch |= e.obj[{}].assign(p, {});", u.layerOrObject, u.keepOrValue ? "true" : "false"));
        }
    }
}

void emitObjectUpdates(CodeWriter& out, const Game& g, const BitSet& set, const BitSet& clear, const CellFacts* facts) {
    emitObjectUpdates(out, objectUpdates(g, set, clear, facts));
}

void emitMovementUpdates(CodeWriter& out, const Game& g, const ir::Replacement& r, std::optional<int> entityLayer,
                         const CellFacts* facts) {
    for (const MovementUpdate& u : movementUpdates(g, r, entityLayer, facts)) {
        if (u.randomDirection) {
            out.line(fmt::format("ch |= putMovement(e, p, {}, {}u, {}u | (1u << rd{}));", u.layer, u.clear, u.set, u.layer));
        } else {
            out.line(fmt::format("ch |= putMovement(e, p, {}, {}u, {}u);", u.layer, u.clear, u.set));
        }
    }
}

void emitRigidClaim(CodeWriter& out, const Game& g, const Rule& rule, const ir::Replacement& r) {
    const RigidClaim claim = rigidClaim(g, rule, r);
    std::vector<std::string> groupMissing;
    std::vector<std::string> appliedMissing;
    std::vector<std::string> claims;
    for (int L : claim.layers) {
        for (int k = 0; k < 5; ++k) {
            if (!((claim.claim >> k) & 1)) continue;
            groupMissing.push_back(fmt::format("!t.rigidGroup[{}].test(p)", 5 * L + k));
            claims.push_back(fmt::format("t.rigidGroup[{}].set(p);", 5 * L + k));
        }
        appliedMissing.push_back(fmt::format("!t.rigidApplied[{}].test(p)", L));
        claims.push_back(fmt::format("t.rigidApplied[{}].set(p);", L));
    }
    if (groupMissing.empty()) return;
    out.open(fmt::format("if (({}) && ({}))", joinWith(groupMissing, " || "), joinWith(appliedMissing, " || ")));
    for (const auto& c : claims) out.line(c);
    out.line("ch = true;");
    out.close();
}

// `facts`: what the cell's pattern says of it, where that holds (knownFacts), or null.
void emitReplacement(CodeWriter& out, const Game& g, const Rule& rule, const CellPattern& cell, const std::string& pos,
                     const CellFacts* facts) {
    const ir::Replacement& r = *cell.replacement;
    out.open("");
    out.line("const int p = " + pos + ";");
    const std::vector<int> candidates = r.randomEntity.bits();
    if (!candidates.empty()) out.line(fmt::format("const int pick = e.rng.below({});", candidates.size()));
    for (int L = 0; L < g.layerCount; ++L) {
        if (r.randomDirMask.test(static_cast<size_t>(5 * L))) out.line(fmt::format("const int rd{} = e.rng.below(4);", L));
    }
    out.line("bool ch = false;");
    if (candidates.empty()) {
        emitObjectUpdates(out, g, r.set, r.clear, facts);
        emitMovementUpdates(out, g, r, std::nullopt, facts);
    } else {
        out.open("switch (pick)");
        for (size_t i = 0; i < candidates.size(); ++i) {
            const int id = candidates[i];
            const int layer = layerOfObject(g, id);
            BitSet set = r.set;
            BitSet clear = r.clear;
            set.set(static_cast<size_t>(id));
            if (layer >= 0) clear |= g.layerMasks[static_cast<size_t>(layer)];
            out.open(fmt::format("case {}:", i));
            out.line(fmt::format("// {}", g.objects[static_cast<size_t>(id)].name));
            emitObjectUpdates(out, g, set, clear, facts);
            emitMovementUpdates(out, g, r, layer >= 0 ? std::optional<int>(layer) : std::nullopt, facts);
            out.line("break;");
            out.close();
        }
        out.close();
    }
    if (rule.rigid) emitRigidClaim(out, g, rule, r);
    out.line("changed |= ch;");
    out.close();
}

// Row `index` of the match; `layersExclusive`: layersHoldOneObject(g).
void emitApplyRow(CodeWriter& out, const Game& g, const Rule& rule, const RowLayout& row, size_t index,
                  bool layersExclusive) {
    for (size_t i = 0; i < row.cells->size(); ++i) {
        const CellPattern& c = (*row.cells)[i];
        if (c.ellipsis || !c.replacement) continue;
        const std::optional<CellFacts> facts = knownFacts(g, rule, index, c, layersExclusive);
        emitReplacement(out, g, rule, c, row.position(i), facts ? &*facts : nullptr);
    }
}

// Whether the replacement of a cell of row `row` writes nothing its pattern
// leaves open (CellFacts), as `[ Crate | ... ] -> [ Crate | ... ]`'s first cell.
bool changesNothing(const Game& g, const Rule& rule, size_t row, const CellPattern& cell, bool layersExclusive) {
    const ir::Replacement& r = *cell.replacement;
    const std::optional<CellFacts> facts = knownFacts(g, rule, row, cell, layersExclusive);
    if (!facts || r.randomEntity.any() || r.randomDirMask.any()) return false;
    return objectUpdates(g, r.set, r.clear, &*facts).empty() && movementUpdates(g, r, std::nullopt, &*facts).empty();
}

// Where a rule's one changing cell is: its row and its place in the row.
struct WriterCell {
    size_t row = 0;
    size_t cell = 0;
};

// The cell whose replacement a rule's matches can all apply at once, as
// board operations, instead of one after another; none where they cannot.
// That takes rows without gaps and one cell of them that changes anything:
// each position of its row's matches is then written once (a second match
// through the same position would rewrite what the first wrote, so skipping
// it changes nothing), and where a write lands on another match's cell, of
// any row, that cell must still match after it, so every match still stands
// after the others (the matches a write makes are not among those found,
// and wait for the rule's next pass, as in the reference).  Random draws and
// rigid claims depend on the order: not those.
std::optional<WriterCell> appliesAtOnce(const Game& g, const Rule& rule, bool layersExclusive) {
    if (rule.rigid || hasEllipsis(rule)) return std::nullopt;
    std::optional<WriterCell> writer;
    for (size_t r = 0; r < rule.rows.size(); ++r) {
        for (size_t i = 0; i < rule.rows[r].size(); ++i) {
            const CellPattern& c = rule.rows[r][i];
            if (!c.replacement || changesNothing(g, rule, r, c, layersExclusive)) continue;
            if (writer) return std::nullopt;
            writer = WriterCell{r, i};
        }
    }
    if (!writer) return std::nullopt;
    const CellPattern& writerCell = rule.rows[writer->row][writer->cell];
    const ir::Replacement& w = *writerCell.replacement;
    if (w.randomEntity.any() || w.randomDirMask.any()) return std::nullopt;
    const std::optional<CellFacts> facts = knownFacts(g, rule, writer->row, writerCell, layersExclusive);
    const ReplacementEffect effect = effectOf(w, facts ? &*facts : nullptr);
    for (size_t r = 0; r < rule.rows.size(); ++r) {
        for (size_t j = 0; j < rule.rows[r].size(); ++j) {
            if (r == writer->row && j == writer->cell) continue;
            const CellPattern& c = rule.rows[r][j];
            // A match whose cell lies where another match writes was found
            // with both patterns holding there: never where they exclude.
            if (layersExclusive && cellsExclude(g, writerCell, c)) continue;
            if (!stillMatchesAfter(c, effect)) return std::nullopt;
        }
    }
    return writer;
}

// The replacement at every position of board `at` (appliesAtOnce).
void emitApplyAtOnce(CodeWriter& out, const Game& g, const ir::Replacement& r, const CellFacts* known,
                     const std::string& at) {
    for (const ObjectUpdate& u : objectUpdates(g, r.set, r.clear, known)) {
        if (u.kind == ObjectUpdate::kAssign) {
            out.line(fmt::format("changed |= e.obj[{}].assignWhere({}, {});", u.layerOrObject, at, u.keepOrValue ? "true" : "false"));
        } else {
            out.line(fmt::format("changed |= putLayer{}Where(e, {}, {});", u.layerOrObject, at, u.keepOrValue));
        }
    }
    for (const MovementUpdate& u : movementUpdates(g, r, std::nullopt, known)) {
        out.line(fmt::format("changed |= putMovementWhere(e, {}, {}, {}u, {}u);", at, u.layer, u.clear, u.set));
    }
}

// The statement that queues the rule's commands (`commands` != 0).
std::string queueStatement(const Rule& rule, uint32_t commands, const std::vector<std::string>& messages) {
    const int message = messageIndex(rule, messages);
    if (message < 0) return fmt::format("e.queue = queueCommands(e.queue, {}u);", commands);
    return fmt::format("queueMessageRule(e, {}u, {});", commands, message);
}

// Whether a rule applied match by match also gets the path for one match a
// row (emitOneMatchPath): rules of several rows without gaps, no rigid
// claims and no random draws.  A rule of one row keeps its loop: its
// matches' cells are its one row's, and slidings, limerick, dictionary and
// match3 stepped 0.93-0.98x as fast with the path there too.
bool takesOneMatchPath(const Rule& rule) {
    if (rule.rows.size() < 2 || rule.rigid || hasEllipsis(rule)) return false;
    for (const auto& row : rule.rows) {
        for (const CellPattern& c : row) {
            if (c.replacement && (c.replacement->randomEntity.any() || c.replacement->randomDirMask.any())) return false;
        }
    }
    return true;
}

// Where every row matches once (one player, one counter), the rule's matches
// are one tuple, which holds as found: its writes are board operations at
// each cell's one-bit board, in the loops' order, without the loops or the
// positions' arithmetic.  Compiled where PSC_MASK_WRITES is set
// (templates/core.h).
void emitOneMatchPath(CodeWriter& out, const Game& g, const Rule& rule, uint32_t commands,
                      const std::vector<std::string>& messages, bool layersExclusive) {
    std::vector<std::string> once;
    for (size_t r = 0; r < rule.rows.size(); ++r) once.push_back(fmt::format("row{}.count() == 1", r));
    out.raw("#if PSC_MASK_WRITES\n");
    out.open("if (" + joinWith(once, " && ") + ")");
    for (size_t r = 0; r < rule.rows.size(); ++r) {
        for (size_t i = 0; i < rule.rows[r].size(); ++i) {
            const CellPattern& c = rule.rows[r][i];
            if (!c.replacement) continue;
            const std::optional<CellFacts> facts = knownFacts(g, rule, r, c, layersExclusive);
            out.open("");
            out.line(i == 0 ? fmt::format("const Board& at = row{};", r)
                            : fmt::format("const Board at = shiftBySteps<{0}>(row{1}, -{0} * d);", i, r));
            emitApplyAtOnce(out, g, *c.replacement, facts ? &*facts : nullptr, "at");
            out.close();
        }
    }
    if (commands) out.line(queueStatement(rule, commands, messages));
    out.line("return changed;");
    out.close();
    out.raw("#endif\n");
}

// ---- whole rules

struct RuleNames {
    std::string apply;  // tryApply
    std::string count;  // number of candidate matches (random groups)
    std::string nth;    // apply the n-th candidate (random groups)
    std::string needs;  // whether the boards it needs hold something (presenceTest), or empty
};

// Whether every board of `needs` (presence bits: RuleParts' neededPresence)
// holds something, as a C++ condition over Env e; empty where none is needed.
std::string presenceTest(const Game& g, const std::vector<uint64_t>& needs) {
    const int objects = std::max(1, g.objectCount);
    std::string test;
    for (int bit = 0; bit < 64 * static_cast<int>(needs.size()); ++bit) {
        if (!((needs[static_cast<size_t>(bit / 64)] >> (bit % 64)) & 1)) continue;
        if (!test.empty()) test += " && ";
        test += bit < objects ? fmt::format("e.obj[{}].any()", bit) : fmt::format("e.mov[{}].any()", bit - objects);
    }
    return test;
}

// Emits the nested loops over all rows (last row outermost, so that row 0
// varies fastest) around `action`.
template <typename Action>
void emitTupleLoops(CodeWriter& out, const Rule& rule, Action action) {
    std::vector<RowLayout> rows;
    for (size_t r = 0; r < rule.rows.size(); ++r) rows.push_back(layoutOf(rule, r));
    std::function<void(int)> nest = [&](int r) {
        if (r < 0) {
            action(rows);
            return;
        }
        emitRowLoops(out, rule, rows[static_cast<size_t>(r)], [&] { nest(r - 1); });
    };
    nest(static_cast<int>(rows.size()) - 1);
}

// The rule's step, its rows' boards, and an early return (of `noMatch`) when a row cannot match.
void emitRowSetup(CodeWriter& out, const Rule& rule, const std::string& noMatch) {
    out.line("const int d = " + stepExpr(rule.direction) + ";");
    out.line("(void)d;");
    for (size_t r = 0; r < rule.rows.size(); ++r) emitRowBoards(out, layoutOf(rule, r));
    std::vector<std::string> empty;
    for (size_t r = 0; r < rule.rows.size(); ++r) empty.push_back(fmt::format("!row{}.any()", r));
    out.line("if (" + joinWith(empty, " || ") + ") return " + noMatch + ";");
}

// A rule function's first lines: one out of line (PSC_RULE_APART) is told
// that its state lies on the stack (PSC_ON_STACK, templates/core.h); one
// inlined sees where its caller's state lies.
void emitStatePrologue(CodeWriter& out, const std::string& kind) {
    if (kind == "PSC_RULE_APART") {
        out.line("PSC_ON_STACK(e);");
        out.line("PSC_ON_STACK(t);");
    } else {
        out.line("(void)t;");
    }
}

// `layersExclusive`: layersHoldOneObject(g), so that a cell's pattern tells what it holds.
// `oneMatchPaths`: RuleUnits::oneMatchPaths.
void emitRule(CodeWriter& out, const Game& g, const Rule& rule, const RuleNames& names, bool inRandomGroup,
              const std::vector<std::string>& messages, const std::string& kind, bool layersExclusive, bool oneMatchPaths) {
    out.line("// line " + std::to_string(rule.line) + ": " + ir::ruleText(g, rule));
    const uint32_t commands = commandBits(rule);
    if (!inRandomGroup) {
        out.open("PSC_DEVICE " + kind + " bool " + names.apply + "(Env& e, Turn& t)");
        emitStatePrologue(out, kind);
        emitRowSetup(out, rule, "false");
        out.line("bool changed = false;");
        if (const std::optional<WriterCell> writer = appliesAtOnce(g, rule, layersExclusive)) {
            const CellPattern& cell = rule.rows[writer->row][writer->cell];
            std::string at = fmt::format("row{}", writer->row);
            if (writer->cell > 0) {
                out.line(fmt::format("const Board at = shiftBySteps<{}>({}, -{} * d);", writer->cell, at, writer->cell));
                at = "at";
            }
            const std::optional<CellFacts> facts = knownFacts(g, rule, writer->row, cell, layersExclusive);
            emitApplyAtOnce(out, g, *cell.replacement, facts ? &*facts : nullptr, at);
            if (commands) out.line(queueStatement(rule, commands, messages));
        } else if (rule.hasReplacements) {
            if (oneMatchPaths && takesOneMatchPath(rule)) emitOneMatchPath(out, g, rule, commands, messages, layersExclusive);
            out.line("bool first = true;");
            emitTupleLoops(out, rule, [&](const std::vector<RowLayout>& rows) {
                std::vector<std::string> checks;
                for (const auto& row : rows) checks.push_back(recheck(row));
                out.line("if (!first && !(" + joinWith(checks, " && ") + ")) continue;");
                out.line("first = false;");
                for (size_t r = 0; r < rows.size(); ++r) emitApplyRow(out, g, rule, rows[r], r, layersExclusive);
            });
            if (commands) out.line("if (!first) " + queueStatement(rule, commands, messages));
        } else {
            if (!hasEllipsis(rule)) {
                if (commands) out.line(queueStatement(rule, commands, messages));
            } else {
                out.line("bool matched = false;");
                emitTupleLoops(out, rule, [&](const std::vector<RowLayout>&) { out.line("matched = true;"); });
                if (commands) out.line("if (matched) " + queueStatement(rule, commands, messages));
            }
        }
        out.line("return changed;");
        out.close();
        out.line();
        return;
    }

    // In a random group: count the candidates, and apply the n-th.
    out.open("PSC_DEVICE " + kind + " long long " + names.count + "(const Env& e)");
    if (kind == "PSC_RULE_APART") out.line("PSC_ON_STACK(e);");
    emitRowSetup(out, rule, "0");
    if (!hasEllipsis(rule)) {
        std::vector<std::string> counts;
        for (size_t r = 0; r < rule.rows.size(); ++r) counts.push_back(fmt::format("static_cast<long long>(row{}.count())", r));
        out.line("return " + joinWith(counts, " * ") + ";");
    } else {
        out.line("long long n = 0;");
        emitTupleLoops(out, rule, [&](const std::vector<RowLayout>&) { out.line("++n;"); });
        out.line("return n;");
    }
    out.close();
    out.line();

    out.open("PSC_DEVICE " + kind + " bool " + names.nth + "(Env& e, Turn& t, long long n)");
    emitStatePrologue(out, kind);
    emitRowSetup(out, rule, "false");
    out.line("bool changed = false;");
    out.line("long long index = 0;");
    emitTupleLoops(out, rule, [&](const std::vector<RowLayout>& rows) {
        out.open("if (index++ == n)");
        for (size_t r = 0; r < rows.size(); ++r) emitApplyRow(out, g, rule, rows[r], r, layersExclusive);
        out.close();
    });
    if (commands) out.line(queueStatement(rule, commands, messages));
    out.line("return changed;");
    out.close();
    out.line();
}

// `first == v ? values[v] : ...` over a direction set's copies; the value itself where all are equal.
std::string chosenValue(const std::vector<std::string>& values) {
    if (std::all_of(values.begin(), values.end(), [&](const std::string& v) { return v == values[0]; })) return values[0];
    std::string chosen = values.back();
    for (size_t v = values.size() - 1; v-- > 0;) chosen = fmt::format("first == {} ? {} : {}", v, values[v], chosen);
    return "(" + chosen + ")";
}

// For each copy of a direction set, the condition, evaluated before the
// applied copy writes, without which it cannot match once that copy and the
// copies between the two have run: every board it needs (neededPresence)
// that none of them sets is non-empty.  Empty where there is no such board
// (the copy runs whenever it comes after the applied one).  Notsnake's other
// three directions, whose movement boards stay empty, are not called.
std::vector<std::string> laterCopyConditions(const Game& g, const std::vector<Rule>& rules, const DirectionSet& set,
                                             bool layersExclusive) {
    const int words = presenceWords(g);
    std::vector<std::vector<uint64_t>> written;  // by copy
    for (size_t v = 0; v < set.count; ++v) written.push_back(setPresence(g, rules[set.first + v], words, layersExclusive));
    std::vector<std::string> conditions(set.count);
    for (size_t w = 1; w < set.count; ++w) {
        const std::vector<uint64_t> needs = neededPresence(g, rules[set.first + w], words);
        std::vector<std::string> tests;  // by the applied copy, one before w
        bool any = false;
        for (size_t v = 0; v < w; ++v) {
            std::vector<uint64_t> unwritten = needs;
            for (size_t u = v; u < w; ++u) {
                for (size_t i = 0; i < unwritten.size(); ++i) unwritten[i] &= ~written[u][i];
            }
            const std::string test = presenceTest(g, unwritten);
            any = any || !test.empty();
            tests.push_back(test.empty() ? "true" : "(" + test + ")");
        }
        if (any) conditions[w] = chosenValue(tests);
    }
    return conditions;
}

// A direction set's function (DirectionVariants): finds the first copy that
// matches; where it matches once, every thread that found one applies it
// through one code path, the copy's step, cell offsets and movement bits as
// values, so that a warp's environments stay together whichever way their
// inputs went.  The later copies then run as they are, where they still can
// match (laterCopyConditions), as does the first where it matches more than
// once (the scan order then matters).  `copies`: the copies' functions.
void emitDirectionSet(CodeWriter& out, const Game& g, const std::vector<Rule>& rules, const DirectionSet& set,
                      const std::vector<RuleNames>& copies, const std::string& name, const std::string& kind,
                      const std::vector<std::string>& messages, bool layersExclusive) {
    const Rule& lead = rules[set.first];
    out.line(fmt::format("// line {}: its {} direction copies above, a match of any applied by one code path", lead.line,
                         set.count));
    out.open("PSC_DEVICE " + kind + " bool " + name + "(Env& e, Turn& t)");
    std::vector<std::string> matches;
    std::vector<std::string> steps;
    for (size_t v = 0; v < set.count; ++v) {
        const Rule& copy = rules[set.first + v];
        const std::string prefix = fmt::format("v{}_", v);
        out.line(fmt::format("const int {}d = {};", prefix, stepExpr(copy.direction)));
        steps.push_back(prefix + "d");
        std::string needs;
        if (!copies[v].needs.empty()) {
            needs = prefix + "needs";
            out.line(fmt::format("const bool {} = PSC_RULE_NEEDS({});", needs, copies[v].needs));
        }
        std::vector<std::string> tests;
        for (size_t r = 0; r < copy.rows.size(); ++r) {
            emitRowBoards(out, layoutOf(copy, r), prefix, needs);
            tests.push_back(fmt::format("{}row{}.any()", prefix, r));
        }
        matches.push_back(joinWith(tests, " && "));
    }
    std::vector<std::string> live = laterCopyConditions(g, rules, set, layersExclusive);
    std::string first = "-1";
    for (size_t v = set.count; v-- > 0;) first = fmt::format("{} ? {} : {}", matches[v], v, first);
    out.line("const int first = " + first + ";");
    out.line("if (first < 0) return false;");
    for (size_t w = 1; w < set.count; ++w) {
        if (live[w].empty()) continue;
        out.line(fmt::format("const bool v{}_live = {};", w, live[w]));
        live[w] = fmt::format("v{}_live", w);
    }
    out.line("bool changed = false;");
    std::vector<std::string> once;
    for (size_t r = 0; r < lead.rows.size(); ++r) {
        std::vector<std::string> chosen;
        for (size_t v = 0; v < set.count; ++v) chosen.push_back(fmt::format("onlyIf(v{}_row{}, first == {})", v, r, v));
        out.line(fmt::format("const Board row{} = {};", r, joinWith(chosen, " | ")));
        once.push_back(fmt::format("row{}.count() == 1", r));
    }
    out.line("const bool once = " + joinWith(once, " && ") + ";");
    out.open("if (once)");
    out.line("const int d = " + chosenValue(steps) + ";");
    for (size_t r = 0; r < lead.rows.size(); ++r) {
        out.raw("#if !PSC_MASK_WRITES\n");
        out.line(fmt::format("const int s{0} = row{0}.lowest();", r));
        out.raw("#endif\n");
        for (size_t j = 0; j < lead.rows[r].size(); ++j) {
            const CellUpdates leadUpdates = cellUpdates(g, lead, r, j, layersExclusive);
            if (leadUpdates.objects.empty() && leadUpdates.movements.empty()) continue;
            std::vector<std::string> offsets;
            std::vector<CellUpdates> updates;
            for (size_t v = 0; v < set.count; ++v) {
                const size_t cell = set.cellOf[v][r][j];
                offsets.push_back(std::to_string(cell));
                updates.push_back(cellUpdates(g, rules[set.first + v], r, cell, layersExclusive));
            }
            // The cell's writes at its position, or at its one-bit board
            // where PSC_MASK_WRITES is set (templates/core.h).
            out.open("");
            size_t furthest = 0;
            for (size_t v = 0; v < set.count; ++v) furthest = std::max(furthest, set.cellOf[v][r][j]);
            std::vector<std::string> maskWrites;
            for (const ObjectUpdate& u : leadUpdates.objects) {
                maskWrites.push_back(u.kind == ObjectUpdate::kPutLayer
                                         ? fmt::format("ch |= putLayer{}Where(e, at, {});", u.layerOrObject, u.keepOrValue)
                                         : fmt::format("ch |= e.obj[{}].assignWhere(at, {});", u.layerOrObject,
                                                       u.keepOrValue ? "true" : "false"));
            }
            CodeWriter positionWrites(out.indent());
            emitObjectUpdates(positionWrites, leadUpdates.objects);
            for (size_t m = 0; m < leadUpdates.movements.size(); ++m) {
                std::vector<std::string> clears;
                std::vector<std::string> sets;
                uint32_t touched = 0;
                for (const CellUpdates& u : updates) {
                    clears.push_back(fmt::format("{}u", u.movements[m].clear));
                    sets.push_back(fmt::format("{}u", u.movements[m].set));
                    touched |= u.movements[m].clear | u.movements[m].set;
                }
                const std::string clear = chosenValue(clears);
                const std::string put = chosenValue(sets);
                const int layer = leadUpdates.movements[m].layer;
                if (clear == clears[0] && put == sets[0]) {
                    maskWrites.push_back(fmt::format("ch |= putMovementWhere(e, at, {}, {}, {});", layer, clear, put));
                    positionWrites.line(fmt::format("ch |= putMovement(e, p, {}, {}, {});", layer, clear, put));
                } else {
                    maskWrites.push_back(fmt::format("ch |= putMovementChosenWhere(e, at, {}, {}, {}, {}u);", layer, clear, put, touched));
                    positionWrites.line(fmt::format("ch |= putMovementChosen(e, p, {}, {}, {}, {}u);", layer, clear, put, touched));
                }
            }
            out.raw("#if PSC_MASK_WRITES\n");
            out.line(furthest == 0 ? fmt::format("const Board& at = row{};", r)
                                   : fmt::format("const Board at = shiftBySteps<{}>(row{}, -d * {});", furthest, r, chosenValue(offsets)));
            out.line("bool ch = false;");
            for (const std::string& w : maskWrites) out.line(w);
            out.raw("#else\n");
            out.line(fmt::format("const int p = s{} + d * {};", r, chosenValue(offsets)));
            out.line("bool ch = false;");
            out.raw(positionWrites.text());
            out.raw("#endif\n");
            out.line("changed |= ch;");
            out.close();
        }
    }
    if (const uint32_t commands = commandBits(lead)) out.line(queueStatement(lead, commands, messages));
    out.close();
    for (size_t v = 0; v < set.count; ++v) {
        const std::string call = copies[v].apply + "(e, t)";
        const std::string later = live[v].empty() ? fmt::format("first < {}", v) : fmt::format("(first < {} && {})", v, live[v]);
        out.line(fmt::format("if ({} || (first == {} && !once)) changed |= {};", later, v,
                             copies[v].needs.empty() ? call : "(PSC_RULE_NEEDS(" + copies[v].needs + ") && " + call + ")"));
    }
    out.line("return changed;");
    out.close();
    out.line();
}

// A function, or a random rule's two, as code and as declarations: the unit
// of what goes to one compile unit.
struct Piece {
    std::string text;
    std::vector<std::string> declarations;
};

// The group's function: passes over its rules, or (random) one match drawn from all of theirs.
// One pass's calls of a group's rules, each behind the boards it needs.
void emitRuleCalls(CodeWriter& out, const std::vector<RuleNames>& names) {
    for (const auto& n : names) {
        const std::string call = n.apply + "(e, t)";
        out.line("any |= " + (n.needs.empty() ? call : "(PSC_RULE_NEEDS(" + n.needs + ") && " + call + ")") + ";");
    }
}

void emitGroupFunction(CodeWriter& out, const Game& g, const ir::RuleGroup& group, size_t index, bool late,
                       const std::vector<RuleNames>& names, bool inPlace, bool layersExclusive, bool rolledPasses = false) {
    const std::string name = groupName(group, index, late);
    const std::string state = inPlace ? "PSC_GROUP_IN_PLACE(env, turn);" : "PSC_GROUP_WORKING_COPY(env, turn);";
    if (!group.random && passesOnce(g, group, layersExclusive)) {
        out.line(fmt::format("// group {} (line {}): one pass over its rules, after which none can match (passesOnce)", index,
                             group.groupNumber));
        out.open("PSC_DEVICE PSC_GROUP bool " + name + "(Env& env, Turn& turn)");
        out.line(state);
        out.line("bool any = false;");
        emitRuleCalls(out, names);
        out.line("return any;");
        out.close();
        out.line();
        return;
    }
    if (!group.random) {
        out.line(fmt::format("// group {} (line {}): passes over its rules until one changes nothing, at most 200",
                             index, group.groupNumber));
        out.open("PSC_DEVICE PSC_GROUP bool " + name + "(Env& env, Turn& turn)");
        out.line(state);
        out.line("bool changed = false;");
        out.open(std::string(rolledPasses ? "PSC_PASSES " : "") + "for (int pass = 0; pass < 200; ++pass)");
        out.line("bool any = false;");
        emitRuleCalls(out, names);
        out.line("if (!any) break;");
        out.line("changed = true;");
        out.close();
        out.line("return changed;");
        out.close();
        out.line();
        return;
    }
    out.line(fmt::format("// group {} (line {}): random, applies one match drawn from all its rules' matches", index,
                         group.groupNumber));
    out.open("PSC_DEVICE PSC_GROUP bool " + name + "(Env& env, Turn& turn)");
    out.line(state);
    out.line(fmt::format("long long counts[{}];", names.size()));
    out.line("long long total = 0;");
    for (size_t i = 0; i < names.size(); ++i) {
        out.line(fmt::format("counts[{}] = {}(e);", i, names[i].count));
        out.line(fmt::format("total += counts[{}];", i));
    }
    out.line("if (total == 0) return false;");
    out.line("long long pick = static_cast<long long>(e.rng.uniform() * static_cast<double>(total));");
    for (size_t i = 0; i < names.size(); ++i) {
        out.line(fmt::format("if (pick < counts[{}]) return {}(e, t, pick);", i, names[i].nth));
        out.line(fmt::format("pick -= counts[{}];", i));
    }
    out.line("return false;");
    out.close();
    out.line();
}

// A group part's function (the groups layout): some of a large group's
// rules, in order, on a copy of the state; the group passes over its parts.
void emitGroupPart(CodeWriter& out, const std::string& name, const std::vector<RuleNames>& names, const std::string& state) {
    out.open("PSC_DEVICE PSC_GROUP bool " + name + "(Env& env, Turn& turn)");
    out.line(state);
    out.line("bool any = false;");
    for (const auto& n : names) out.line("any |= " + n.apply + "(e, t);");
    out.line("return any;");
    out.close();
    out.line();
}

std::string groupDeclaration(const std::string& name) {
    return "PSC_DEVICE PSC_GROUP bool " + name + "(Env& env, Turn& turn);";
}

// How emitGroup lays a group out.
struct GroupLayout {
    bool together = false;  // the groups layout: the group and its rules as one piece, on a copy
    bool apart = false;     // rules out of line (PSC_RULE_APART), the group in place
    size_t partBytes = 0;   // together: a larger group is split into parts of at most this much code
    bool inSpan = false;    // together, inlined into a span that holds the copy: the group works in place
    bool rolledPasses = false;  // the group's passes stay a loop (RuleUnits::rolledPasses)
    // A rule's direction copies as one (emitDirectionSet).  Not in the groups
    // layout: kettle, its one game with a set among the benchmark's, stepped
    // 15 % slower with it, in the same compile units as without: its crates
    // push in chains of several matches, where the set only adds work
    // (docs/performance.md).
    bool joinDirections = false;
    bool oneMatchPaths = true;  // RuleUnits::oneMatchPaths
};

// A group's pieces: its rules and its function; `inlined` says which pieces
// hold a group with its rules inlined (the groups layout's units 1..groupUnits).
void emitGroup(std::vector<Piece>& pieces, std::vector<bool>& inlined, int indent, const Game& g,
               const ir::RuleGroup& group, size_t index, bool late, const GroupLayout& layout,
               std::set<std::string>& used, const std::vector<std::string>& messages, bool layersExclusive) {
    const std::string kind = layout.apart ? "PSC_RULE_APART" : "PSC_RULE";
    const std::string name = groupName(group, index, late);
    std::vector<RuleNames> names;
    std::vector<Piece> rules;
    size_t bytes = 0;
    const int words = presenceWords(g);
    const std::vector<uint64_t> groupNeeds = groupNeededPresence(g, group, words);
    for (const auto& rule : group.rules) {
        std::string base = uniqueIdentifier(ruleIdentifier(g, rule, late), used);
        // A rule that needs no board beyond the group's is not tested before
        // its call: the turn tested those boards, and the rule's first test is its own.
        const std::vector<uint64_t> needs = neededPresence(g, rule, words);
        names.push_back({base, base + "_count", base + "_apply_nth", needs == groupNeeds ? "" : presenceTest(g, needs)});
        CodeWriter code(indent);
        emitRule(code, g, rule, names.back(), group.random, messages, kind, layersExclusive, layout.oneMatchPaths);
        const RuleNames& n = names.back();
        rules.push_back({code.text(), group.random ? std::vector<std::string>{
                                                         "PSC_DEVICE " + kind + " long long " + n.count + "(const Env& e);",
                                                         "PSC_DEVICE " + kind + " bool " + n.nth + "(Env& e, Turn& t, long long n);"}
                                                   : std::vector<std::string>{"PSC_DEVICE " + kind + " bool " + n.apply +
                                                                              "(Env& e, Turn& t);"}});
        bytes += rules.back().text.size();
    }
    auto add = [&](Piece piece, bool inline_) {
        pieces.push_back(std::move(piece));
        inlined.push_back(inline_);
    };
    auto join = [](std::vector<Piece>::iterator from, std::vector<Piece>::iterator to) {
        Piece joined;
        for (auto it = from; it != to; ++it) {
            joined.text += it->text;
            joined.declarations.insert(joined.declarations.end(), it->declarations.begin(), it->declarations.end());
        }
        return joined;
    };
    // A rule's direction copies go with the function that runs them as one
    // (emitDirectionSet), which the group calls instead; the last set first,
    // so that the earlier ones' indices hold.  Copies applied at once are
    // board operations already; as sets they stepped 10-17 % slower
    // (docs/performance.md, "measured and not taken").
    const std::vector<DirectionSet> sets = layout.joinDirections ? directionSets(g, group, layersExclusive) : std::vector<DirectionSet>{};
    for (auto set = sets.rbegin(); set != sets.rend(); ++set) {
        const auto copies = group.rules.begin() + static_cast<long>(set->first);
        if (std::any_of(copies, copies + static_cast<long>(set->count),
                        [&](const Rule& rule) { return appliesAtOnce(g, rule, layersExclusive).has_value(); })) {
            continue;
        }
        const long from = static_cast<long>(set->first);
        const long to = from + static_cast<long>(set->count);
        const std::string setName = uniqueIdentifier(
            fmt::format("{}rule_L{}_directions", late ? "late_" : "", group.rules[set->first].line), used);
        CodeWriter code(indent);
        emitDirectionSet(code, g, group.rules, *set, std::vector<RuleNames>(names.begin() + from, names.begin() + to), setName,
                         kind, messages, layersExclusive);
        Piece piece = join(rules.begin() + from, rules.begin() + to);
        piece.text += code.text();
        piece.declarations.push_back("PSC_DEVICE " + kind + " bool " + setName + "(Env& e, Turn& t);");
        bytes += code.text().size();
        rules.erase(rules.begin() + from, rules.begin() + to);
        rules.insert(rules.begin() + from, std::move(piece));
        names.erase(names.begin() + from, names.begin() + to);
        names.insert(names.begin() + from, RuleNames{setName, "", "", ""});
    }
    // A copy of the random stream, which rules index at run time, would
    // live in local memory: a group that draws from it works in place.
    const bool inPlace = layout.apart || layout.inSpan || groupUsesRandom(group);
    const std::string state = inPlace ? "PSC_GROUP_IN_PLACE(env, turn);" : "PSC_GROUP_WORKING_COPY(env, turn);";
    const bool split = layout.together && !group.random && layout.partBytes > 0 && bytes > layout.partBytes;
    if (split) {
        // Consecutive rules, each part within partBytes (a larger rule alone).
        std::vector<RuleNames> parts;
        size_t first = 0;
        while (first < rules.size()) {
            size_t last = first + 1;
            size_t size = rules[first].text.size();
            while (last < rules.size() && size + rules[last].text.size() <= layout.partBytes) size += rules[last++].text.size();
            const std::string part = fmt::format("{}_part{}", name, parts.size());
            Piece piece = join(rules.begin() + static_cast<long>(first), rules.begin() + static_cast<long>(last));
            CodeWriter code(indent);
            emitGroupPart(code, part,
                          std::vector<RuleNames>(names.begin() + static_cast<long>(first), names.begin() + static_cast<long>(last)),
                          state);
            piece.text += code.text();
            piece.declarations.push_back(groupDeclaration(part));
            add(std::move(piece), true);
            parts.push_back({part, "", "", ""});
            first = last;
        }
        CodeWriter code(indent);
        emitGroupFunction(code, g, group, index, late, parts, true, layersExclusive);
        add({code.text(), {groupDeclaration(name)}}, false);
        return;
    }
    CodeWriter code(indent);
    emitGroupFunction(code, g, group, index, late, names, inPlace, layersExclusive, layout.rolledPasses);
    Piece function{code.text(), {groupDeclaration(name)}};
    if (layout.apart) {
        for (auto& rule : rules) add(std::move(rule), false);
        add(std::move(function), false);
        return;
    }
    // The group goes to one compile unit with its rules, which it inlines
    // (PSC_RULE, templates/core.h); in the groups layout, on a copy.
    Piece piece = join(rules.begin(), rules.end());
    piece.text += function.text;
    piece.declarations.push_back(function.declarations.front());
    add(std::move(piece), layout.together);
}

// The test before a group's call: every board that all its rules need
// holds something (empty when there is nothing to test).
std::string groupNeedsTest(const Game& g, const ir::RuleGroup& group) {
    return presenceTest(g, groupNeededPresence(g, group, presenceWords(g)));
}

// A span's function: name, and its groups (indices into the early or late groups).
struct Span {
    std::string name;
    bool late = false;
    int unit = 1;
    std::vector<size_t> groups;
};

void emitApplyRules(CodeWriter& out, const Game& g, const std::vector<ir::RuleGroup>& groups,
                    const std::map<int, int>& loops, bool late, const std::vector<Span>& spans, const DormantGroups& dormant) {
    const std::string fn = late ? "applyLateRules" : "applyEarlyRules";
    out.line(late ? "// Late rules, in order (with their loops)." : "// The rules, in order (with their loops and rigid bans).");
    // Compiled in the turn's unit (PSC_DEFINES_TURN, templates/core.h), declared for all.
    out.line("PSC_DEVICE PSC_TURN void " + fn + "(Env& e, Turn& t);");
    out.raw("#if PSC_DEFINES_TURN\n");
    out.open("PSC_DEVICE PSC_TURN void " + fn + "(Env& e, Turn& t)");
    out.line("PSC_ON_STACK(e);");
    out.line("PSC_ON_STACK(t);");
    if (!spans.empty()) {
        for (const auto& span : spans) {
            if (span.late == late) out.line(span.name + "(e, t);");
        }
        out.close();
        out.raw("#endif\n");
        out.line();
        return;
    }
    const std::vector<bool>& canSleep = late ? dormant.late : dormant.early;
    auto call = [&](size_t i) {
        std::string c = groupName(groups[i], i, late) + "(e, t)";
        if (canSleep[i]) c = "(" + c + " && (t.dormantGroupMatched = 1))";
        const std::string needs = groupNeedsTest(g, groups[i]);
        if (!needs.empty()) c = "(PSC_GROUP_NEEDS(" + needs + ") && " + c + ")";
        if (canSleep[i]) c = "(!e.dormant && " + c + ")";
        if (!late) {
            auto it = g.groupIndexToRigidGroupIndex.find(static_cast<int>(i));
            if (it != g.groupIndexToRigidGroupIndex.end()) {
                return fmt::format("(((t.banned >> {}) & 1u) == 0 && {})", it->second, c);
            }
        }
        return c;
    };
    if (loops.empty()) {
        for (size_t i = 0; i < groups.size(); ++i) out.line(call(i) + ";");
    } else {
        out.line("int i = 0;");
        out.line("bool propagated = false;");
        out.line("int jumps = 0;");
        out.open(fmt::format("while (i < {})", groups.size()));
        out.line("bool ran = false;");
        out.open("switch (i)");
        for (size_t i = 0; i < groups.size(); ++i) out.line(fmt::format("case {}: ran = {}; break;", i, call(i)));
        out.close();
        out.line("propagated = ran || propagated;");
        std::vector<std::string> cases;
        for (const auto& [from, to] : loops) cases.push_back(fmt::format("i == {} ? {}", from, to));
        out.line("const int loopTo = " + joinWith(cases, " : ") + " : -1;");
        out.open("if (propagated && loopTo >= 0)");
        out.line("i = loopTo;");
        out.line("propagated = false;");
        out.line("if (++jumps > 200) break;");
        out.line("continue;");
        out.close();
        out.line("++i;");
        out.close();
    }
    out.close();
    out.raw("#endif\n");
    out.line();
}

// The groups layout in spans (RuleUnits::spans): each group with its rules
// inlined, working in place; runs of consecutive groups to units
// 1..groupUnits by their weight; in each unit a span function a phase that
// copies the state once and runs its groups on the copy.
void emitRuleSpans(CodeWriter& out, const Game& game, const RuleUnits& layout, const DormantGroups& dormant) {
    std::set<std::string> used;
    const std::vector<std::string> messages = ruleMessages(game);
    const bool layersExclusive = layersHoldOneObject(game);
    struct Placed {
        size_t index;
        bool late;
        Piece piece;
        size_t weight;
        int unit = 1;
    };
    std::vector<Placed> placed;
    size_t total = 0;
    for (const bool late : {false, true}) {
        const auto& groups = late ? game.lateRules : game.rules;
        for (size_t i = 0; i < groups.size(); ++i) {
            std::vector<Piece> pieces;
            std::vector<bool> inlined;
            GroupLayout groupLayout;
            groupLayout.together = true;
            groupLayout.inSpan = true;
            emitGroup(pieces, inlined, out.indent(), game, groups[i], i, late, groupLayout, used, messages, layersExclusive);
            const size_t weight = pieces.front().text.size() * layout.copyWeight;
            placed.push_back({i, late, std::move(pieces.front()), weight});
            total += weight;
        }
    }
    // A group goes to the unit its weight's midpoint falls in: runs of
    // consecutive groups, balanced by weight.  No unit is skipped, and each
    // group leaves enough after it for the units after its own, so that no
    // unit is empty where there are as many groups as units (as gpuCode,
    // codegen/CppSource.cpp, sees to): an empty unit costs NVRTC a compile,
    // and, with no symbol of its own, gets internal names that differ from
    // build to build.
    const int units = std::max(layout.groupUnits, 1);
    const int count = static_cast<int>(placed.size());
    std::vector<Span> spans;
    size_t before = 0;
    int previous = 0;
    for (int g = 0; g < count; ++g) {
        Placed& p = placed[static_cast<size_t>(g)];
        const double middle = (static_cast<double>(before) + static_cast<double>(p.weight) / 2) / static_cast<double>(std::max<size_t>(total, 1));
        const int byWeight = 1 + std::min(units - 1, static_cast<int>(middle * units));
        p.unit = std::min(previous + 1, std::max(byWeight, units - (count - g) + 1));
        previous = p.unit;
        before += p.weight;
        if (spans.empty() || spans.back().unit != p.unit || spans.back().late != p.late) {
            spans.push_back({fmt::format("{}_rules_unit{}", p.late ? "late" : "early", p.unit), p.late, p.unit, {}});
        }
        spans.back().groups.push_back(p.index);
    }
    out.line("// The rule groups run in spans, one function a phase in each unit, each on one copy of the state (templates/core.h).");
    for (const auto& span : spans) out.line("PSC_DEVICE PSC_SPAN void " + span.name + "(Env& env, Turn& turn);");
    out.line();
    for (int unit = 1; unit <= units; ++unit) {
        out.raw(fmt::format("#if PSC_COMPILES_UNIT({})\n", unit));
        for (const auto& p : placed) {
            if (p.unit == unit) out.raw(p.piece.text);
        }
        for (const auto& span : spans) {
            if (span.unit != unit) continue;
            out.open("PSC_DEVICE PSC_SPAN void " + span.name + "(Env& env, Turn& turn)");
            out.line("PSC_GROUP_WORKING_COPY(env, turn);");
            const auto& groups = span.late ? game.lateRules : game.rules;
            const std::vector<bool>& canSleep = span.late ? dormant.late : dormant.early;
            for (size_t i : span.groups) {
                // The span's copy of the turn keeps only the rules' changes: the flag goes to the turn itself.
                std::string call = groupName(groups[i], i, span.late) + "(e, t)";
                call = canSleep[i] ? "if (" + call + ") turn.dormantGroupMatched = 1;" : call + ";";
                std::string needs = groupNeedsTest(game, groups[i]);
                if (!needs.empty()) needs = "PSC_GROUP_NEEDS(" + needs + ")";
                if (canSleep[i]) needs = needs.empty() ? "!env.dormant" : "!env.dormant && " + needs;
                out.line(needs.empty() ? call : "if (" + needs + ") " + call);
            }
            out.close();
            out.line();
        }
        out.raw(fmt::format("#endif  // compile unit {}\n", unit));
    }
    out.line();
    emitApplyRules(out, game, game.rules, game.loopPoints, false, spans, dormant);
    emitApplyRules(out, game, game.lateRules, game.lateLoopPoints, true, spans, dormant);
}

}  // namespace

void emitRules(CodeWriter& out, const Game& game, const RuleUnits& layout, std::vector<size_t>* groupBytes) {
    if (layout.groups && layout.spans && !groupBytes) {
        emitRuleSpans(out, game, layout, dormantGroups(game));
        return;
    }
    std::vector<Piece> pieces;
    std::vector<bool> inlined;  // of pieces: a group with its rules inlined (the groups layout)
    std::set<std::string> used;
    const std::vector<std::string> messages = ruleMessages(game);
    const bool layersExclusive = layersHoldOneObject(game);
    auto emitGroupPieces = [&](const ir::RuleGroup& group, size_t index, bool late) {
        const size_t number = index + (late ? game.rules.size() : 0);
        GroupLayout groupLayout;
        groupLayout.together = layout.groups;
        groupLayout.apart = number < layout.apart.size() && layout.apart[number];
        groupLayout.partBytes = layout.partBytes;
        groupLayout.joinDirections = layout.directionSets && !layout.groups;
        groupLayout.rolledPasses = layout.rolledPasses;
        groupLayout.oneMatchPaths = layout.oneMatchPaths;
        const size_t before = pieces.size();
        emitGroup(pieces, inlined, out.indent(), game, group, index, late, groupLayout, used, messages, layersExclusive);
        if (groupBytes) {
            size_t bytes = 0;
            for (size_t i = before; i < pieces.size(); ++i) bytes += pieces[i].text.size();
            groupBytes->push_back(bytes);
        }
    };
    for (size_t i = 0; i < game.rules.size(); ++i) emitGroupPieces(game.rules[i], i, false);
    for (size_t i = 0; i < game.lateRules.size(); ++i) emitGroupPieces(game.lateRules[i], i, true);
    // Inlined groups cost NVRTC more per byte (RuleUnits::copyWeight).
    std::vector<size_t> weights;
    for (size_t i = 0; i < pieces.size(); ++i) weights.push_back(pieces[i].text.size() * (inlined[i] ? layout.copyWeight : 1));
    const int units = layout.units;
    if (units <= 1) {
        for (const auto& piece : pieces) out.raw(piece.text);
    } else {
        // Pieces go to units 1.. (unit 0 has the turn and the kernels),
        // heaviest first, each to the unit of its kind with the least weight
        // so far: inlined groups to units 1..groupUnits, the others after.
        std::vector<size_t> order(pieces.size());
        for (size_t i = 0; i < order.size(); ++i) order[i] = i;
        std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return weights[a] > weights[b]; });
        std::vector<size_t> load(static_cast<size_t>(units), 0);
        std::vector<size_t> unitOf(pieces.size(), 0);
        const size_t split = layout.groups ? static_cast<size_t>(std::clamp(layout.groupUnits, 0, units - 1)) : 0;
        for (size_t i : order) {
            const size_t first = inlined[i] || split + 1 >= load.size() ? 1 : split + 1;
            const size_t end = inlined[i] ? std::max<size_t>(split + 1, 2) : load.size();
            size_t least = first;
            for (size_t k = first + 1; k < end; ++k) least = load[k] < load[least] ? k : least;
            unitOf[i] = least;
            load[least] += weights[i];
        }
        out.line("// Each rule and group is defined in one compile unit (templates/core.h), and declared here for all.");
        for (const auto& piece : pieces) {
            for (const auto& declaration : piece.declarations) out.line(declaration);
        }
        out.line();
        for (size_t k = 1; k < load.size(); ++k) {
            out.raw(fmt::format("#if PSC_COMPILES_UNIT({})\n", k));
            for (size_t i = 0; i < pieces.size(); ++i) {
                if (unitOf[i] == k) out.raw(pieces[i].text);
            }
            out.raw(fmt::format("#endif  // compile unit {}\n", k));
        }
        out.line();
    }
    const DormantGroups dormant = dormantGroups(game);
    emitApplyRules(out, game, game.rules, game.loopPoints, false, {}, dormant);
    emitApplyRules(out, game, game.lateRules, game.lateLoopPoints, true, {}, dormant);
}

bool groupUsesRandom(const ir::RuleGroup& group) {
    if (group.random) return true;
    for (const auto& rule : group.rules) {
        for (const auto& row : rule.rows) {
            for (const auto& c : row) {
                if (c.replacement && (c.replacement->randomEntity.any() || c.replacement->randomDirMask.any())) return true;
            }
        }
    }
    return false;
}

std::vector<std::string> ruleMessages(const Game& game) {
    std::vector<std::string> texts;
    for (const auto* groups : {&game.rules, &game.lateRules}) {
        for (const auto& group : *groups) {
            for (const auto& rule : group.rules) {
                const std::string* message = messageOf(rule);
                if (message && std::find(texts.begin(), texts.end(), *message) == texts.end()) texts.push_back(*message);
            }
        }
    }
    return texts;
}

}  // namespace psc::codegen
