#include "Compiler.h"

#include "parse/Scanner.h"
#include "passes/BuildLevels.h"
#include "passes/BuildMasks.h"
#include "passes/CheckLayers.h"
#include "passes/EncodeRules.h"
#include "passes/ExpandDirections.h"
#include "passes/ExpandMovements.h"
#include "passes/ExpandProperties.h"
#include "passes/GroupRules.h"
#include "passes/LoopPoints.h"
#include "passes/MarkSpawnedStationary.h"
#include "passes/ReadMetadata.h"
#include "passes/ReadRules.h"
#include "passes/RemoveDuplicateRules.h"
#include "passes/ResolveLegend.h"
#include "passes/SimplifyNoClauses.h"
#include "passes/SoundTables.h"
#include "passes/WinConditions.h"

namespace psc {
namespace {

constexpr int kMaxErrorsToPlay = 5;

bool declared(const ast::Game& g, const std::string& name) {
    if (g.findObject(name)) return true;
    for (const auto* list : {&g.synonyms, &g.aggregates, &g.properties}) {
        for (const auto& e : *list) {
            if (e.name == name) return true;
        }
    }
    return false;
}

// The lowering pipeline, in the reference compiler's order.  Returns false
// when the game is invalid (the reference's loadFile returns null).
bool lower(ast::Game& source, Diagnostics& diag, ir::Game& game) {
    if (!declared(source, "player")) diag.error(std::nullopt, "the game has no PLAYER (define an object or legend entry called player)");
    if (!declared(source, "background")) diag.error(std::nullopt, "the game has no BACKGROUND (define an object or legend entry called background)");
    if (source.collisionLayers.empty()) {
        diag.error(std::nullopt, "there are no collision layers; every object must be in one");
        return false;
    }
    passes::CompileState state(source, diag, game);
    passes::resolveLegend(state);
    passes::buildMasks(state);
    passes::buildLevels(state);
    passes::readRules(state);
    passes::simplifyNoClauses(state);
    passes::expandDirections(state);
    if (state.invalid) return false;
    passes::expandMovements(state);
    passes::expandProperties(state);
    passes::markSpawnedStationary(state);
    if (state.invalid) return false;
    passes::removeDuplicateRules(state);
    passes::encodeRules(state);
    passes::groupRules(state);
    passes::buildWinConditions(state);
    passes::checkLayers(state);
    passes::readMetadata(state);
    passes::findLoopPoints(state);
    passes::buildSoundTables(state);
    return true;
}

}  // namespace

const char* statusName(CompileStatus status) {
    switch (status) {
        case CompileStatus::Ok: return "ok";
        case CompileStatus::Playable: return "playable-with-errors";
        case CompileStatus::Refused: return "refused";
        case CompileStatus::Invalid: return "invalid";
        case CompileStatus::ParseGaveUp: return "parse-aborted";
        case CompileStatus::Aborted: return "exception";
    }
    return "?";
}

CompileResult parseSource(std::string_view source) {
    CompileResult result;
    try {
        result.ast = parse::scanGame(source, result.diagnostics);
        result.status = result.diagnostics.errorCount() > 0 ? CompileStatus::Playable : CompileStatus::Ok;
    } catch (const parse::ParseGaveUp&) {
        result.status = CompileStatus::ParseGaveUp;
    } catch (const CompileAborted& e) {
        result.status = CompileStatus::Aborted;
        result.abortReason = e.what();
    }
    return result;
}

CompileResult compileSource(std::string_view source) {
    CompileResult result = parseSource(source);
    if (!result.ast) return result;
    ast::Game working = *result.ast;
    ir::Game game;
    try {
        if (!lower(working, result.diagnostics, game)) {
            result.status = CompileStatus::Invalid;
            return result;
        }
        if (game.levels.empty()) result.diagnostics.urgentError(std::nullopt, "the game has no levels");
    } catch (const CompileAborted& e) {
        result.status = CompileStatus::Aborted;
        result.abortReason = e.what();
        return result;
    }
    game.errorCount = result.diagnostics.errorCount();
    int errors = result.diagnostics.errorCount();
    result.status = errors == 0 ? CompileStatus::Ok : errors <= kMaxErrorsToPlay ? CompileStatus::Playable
                                                                                  : CompileStatus::Refused;
    result.game = std::move(game);
    return result;
}

}  // namespace psc
