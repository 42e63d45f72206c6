// ---- psc template: the turn ----------------------------------------------
// The reference engine's turn and the harness around it, over the game's
// generated rules: player movement, rule groups, movement resolution, the
// rigid-body retry loop, late rules, require_player_movement, the command
// queue (cancel, restart, win, checkpoint, again with its dry run), undo,
// restart and level changes.  Names follow the reference where they help
// compare (processInput, processCommandQueue, doUndo, doRestart, nextLevel).

namespace psc_game {

// A turn with no input, out of line: the level-start turn of
// run_rules_on_level_start (dontDoWin) and the again turns after it.
PSC_DEVICE PSC_COLD void coldTurn(Env& e, UndoStack& u, bool dontDoWin);
// The turn's level changes, defined where PSC_DEFINES_LEVEL_CHANGES
// (templates/core.h), declared for all.
PSC_DEVICE PSC_LEVEL_CHANGE void doRestart(Env& e, UndoStack& u, bool force);
PSC_DEVICE PSC_LEVEL_CHANGE void nextLevel(Env& e, UndoStack& u);
// What a step runs out of line: a new episode (auto-reset) or the undo and
// restart inputs' own work.
PSC_DEVICE PSC_LEVEL_CHANGE void stepEvent(Env& e, UndoStack& u, bool newEpisode, int action);

PSC_DEVICE PSC_INLINE void saveObjects(const Env& e, Snapshot& s) {
    PSC_UNROLL_STATE for (int o = 0; o < kObjects; ++o) s.obj[o] = e.obj[o];
}
PSC_DEVICE PSC_INLINE void loadObjects(Env& e, const Snapshot& s) {
    PSC_UNROLL_STATE for (int o = 0; o < kObjects; ++o) e.obj[o] = s.obj[o];
}
PSC_DEVICE PSC_INLINE bool sameObjects(const Env& e, const Snapshot& s) {
    bool same = true;
    PSC_UNROLL_STATE for (int o = 0; o < kObjects; ++o) same = same && e.obj[o] == s.obj[o];
    return same;
}

// Runs a rare event out of line.  With the state in registers it works on a
// copy of the environment in memory, so that the caller's copy can stay there.
template <typename Event>
PSC_DEVICE PSC_INLINE void outOfLine(Env& e, UndoStack& u, Event event) {
#if defined(__CUDA_ARCH__) && PSC_STATE_IN_REGISTERS
    Env m = e;
    UndoStack mu = u;
    event(m, mu);
    e = m;
    u = mu;
#else
    event(e, u);
#endif
}

// ---- undo history (a ring: when full, the oldest entry is dropped)

// The slot the next entry goes to, the oldest dropped to make room; null
// without an undo history.
PSC_DEVICE PSC_INLINE Snapshot* nextUndo(UndoStack& u) {
    if (u.capacity == 0) return nullptr;
    if (u.count == u.capacity) {
        u.head = (u.head + 1) % u.capacity;
        --u.count;
    }
    return &u.entries[(u.head + u.count++) % u.capacity];
}
PSC_DEVICE PSC_INLINE void pushUndo(UndoStack& u, const Snapshot& s) {
    if (Snapshot* slot = nextUndo(u)) *slot = s;
}
// The level as it is now, saved straight into the history: a snapshot on the
// stack would add a level's worth of objects to every GPU thread's stack.
PSC_DEVICE PSC_INLINE void pushUndoObjects(UndoStack& u, const Env& e) {
    if (Snapshot* slot = nextUndo(u)) saveObjects(e, *slot);
}
PSC_DEVICE PSC_INLINE Snapshot& topUndo(UndoStack& u) { return u.entries[(u.head + u.count - 1) % u.capacity]; }
PSC_DEVICE PSC_INLINE void clearUndo(UndoStack& u) {
    u.count = 0;
    u.head = 0;
}

// The reference clears a level's movements after restoring it by zeroing the
// first width*height words of its movement array; with more than five layers
// (several words per cell) that leaves some cells' movements in place.
// Movements are only non-zero then in games whose late rules use randomdir.
PSC_DEVICE PSC_COLD void clearMovementsLingering(Env& e) {
    const int strideWords = (kLayers + 4) / 5;
    const int cells = e.width * e.height;
    for (int x = 0; x < e.width; ++x) {
        for (int y = 0; y < e.height; ++y) {
            const int index = x * e.height + y;
            const int p = positionOf(e, x, y);
            for (int bit = 0; bit < kLayers * 5; ++bit) {
                if (index * strideWords + bit / 32 < cells) e.mov[bit].clear(p);
            }
        }
    }
}

PSC_DEVICE PSC_INLINE void clearMovementsAfterRestore(Env& e) {
    if (kMovementsCanLinger) {
        clearMovementsLingering(e);
        return;
    }
    PSC_UNROLL_STATE for (int L = 0; L < kLayers; ++L) {
        if (!layerCanMove(L)) continue;
        PSC_UNROLL for (int k = 0; k < 5; ++k) e.mov[5 * L + k] = Board::zero();
    }
}

PSC_DEVICE PSC_INLINE void restoreLevel(Env& e, const Snapshot& s) {
    loadObjects(e, s);
    clearMovementsAfterRestore(e);
    e.dormant = 0;
    e.againing = 0;
    e.queue = 0;
}

// The level as the turn found it, with its dormant groups as they were.
PSC_DEVICE PSC_INLINE void restoreTurnStart(Env& e, const TurnScratch& scratch) {
    restoreLevel(e, scratch.bak);
    if (kHasDormantGroups) e.dormant = scratch.dormantBefore;
}

PSC_DEVICE PSC_COLD void doUndo(Env& e, UndoStack& u, bool force, bool ignoreDuplicates) {
    if (kNoUndo && !force) return;
    if (ignoreDuplicates) {
        while (u.count > 0 && sameObjects(e, topUndo(u))) --u.count;
    }
    if (u.count > 0) {
        restoreLevel(e, topUndo(u));
        --u.count;
    }
}

#if PSC_DEFINES_LEVEL_CHANGES
PSC_DEVICE PSC_LEVEL_CHANGE void doRestart(Env& e, UndoStack& u, bool force) {
    PSC_ON_STACK(e);
    if (e.restarting) return;
    if (!force && kNoRestart) return;
    if (e.againing) doUndo(e, u, force, true);
    e.restarting = 1;
    if (!force) pushUndoObjects(u, e);
    restoreLevel(e, e.restartTarget);
    if (kRunRulesOnLevelStart) coldTurn(e, u, true);
    e.queue = 0;
    e.restarting = 0;
}
#endif

// ---- levels

PSC_DEVICE PSC_INLINE void goToTitleScreen(Env& e) {
    e.againing = 0;
    e.titleScreen = 1;
    e.textMode = 1;
}

// Loads entry e.entry: a level replaces the buffer; a message only shows.
// Either way the random stream restarts from the level seed.
PSC_DEVICE PSC_COLD void loadEntry(Env& e, UndoStack& u) {
#if PSC_USES_RANDOM
    e.rng.seed(e.seed, e.seedLength);
#endif
    e.titleScreen = 0;
    e.againing = 0;
    if (e.entry < 0 || e.entry >= kEntries) {
        goToTitleScreen(e);
        return;
    }
    if (kEntryIsMessage[e.entry]) {
        e.textMode = 1;
        return;
    }
    if (kEntryBoards[e.entry] == -2) {
        // A level left out of this plugin (psc --levels): nothing to play.
        e.unavailable = 1;
        goToTitleScreen(e);
        return;
    }
    e.textMode = 0;
    loadLevelCells(e, e.entry);
    e.dormant = 0;
    e.queue = 0;
    clearUndo(u);
    saveObjects(e, e.restartTarget);
    if (kRunRulesOnLevelStart) coldTurn(e, u, true);
}

#if PSC_DEFINES_LEVEL_CHANGES
PSC_DEVICE PSC_LEVEL_CHANGE void nextLevel(Env& e, UndoStack& u) {
    PSC_ON_STACK(e);
    e.againing = 0;
    if (e.titleScreen) {
        e.entry = 0;
        loadEntry(e, u);
    } else if (e.entry < kEntries - 1) {
        ++e.entry;
        e.textMode = 0;
        e.titleScreen = 0;
        loadEntry(e, u);
    } else {
        e.entry = 0;
        goToTitleScreen(e);
    }
}
#endif

PSC_DEVICE PSC_INLINE void checkWin(Env& e, UndoStack& u, bool dontDoWin) {
    bool won = (e.queue & kCmdWin) != 0;
    if (!won) {
        if (kWinConditionCount == 0) return;
        won = winConditionsHold(e);
    }
    if (won && !dontDoWin) {
        e.againing = 0;
        ++e.wins;
        if (!e.stopOnWin) outOfLine(e, u, [](Env& m, UndoStack& mu) { nextLevel(m, mu); });
    }
}

// ---- the turn

PSC_DEVICE PSC_INLINE u32 queueCommands(u32 queue, u32 commands) {
    if (commands == 0 || (queue & kCmdCancel)) return queue;
    if ((queue & kCmdRestart) && !(commands & kCmdCancel)) return queue;
    if (commands & (kCmdCancel | kCmdRestart)) queue = 0;
    return queue | commands;
}

#if PSC_HAS_RULE_MESSAGES
// queueCommands for a rule with a `message` command: the queue keeps the
// first message text queued since it was last emptied.
PSC_DEVICE PSC_INLINE void queueMessageRule(Env& e, u32 commands, int message) {
    const u32 before = e.queue;
    e.queue = queueCommands(before, commands);
    const bool ignored = (before & kCmdCancel) || ((before & kCmdRestart) && !(commands & kCmdCancel));
    if (!ignored && (!(before & kCmdMessage) || (commands & (kCmdCancel | kCmdRestart)))) {
        e.queuedMessage = static_cast<short>(message);
    }
}

// The reference's player shows a queued message when a turn that is not a
// dry run reaches its command queue (cancelled or restarted turns too); its
// test harness, which psc follows, shows none.  A step reports the first.
PSC_DEVICE PSC_INLINE void noteShownMessage(Env& e) {
    if ((e.queue & kCmdMessage) && e.shownMessage < 0) e.shownMessage = e.queuedMessage;
}
PSC_DEVICE PSC_INLINE void clearShownMessage(Env& e) { e.shownMessage = -1; }
PSC_DEVICE PSC_INLINE int shownMessageOf(const Env& e) { return e.shownMessage; }
#else
PSC_DEVICE PSC_INLINE void noteShownMessage(Env&) {}
PSC_DEVICE PSC_INLINE void clearShownMessage(Env&) {}
PSC_DEVICE PSC_INLINE int shownMessageOf(const Env&) { return -1; }
#endif

PSC_DEVICE PSC_INLINE void clearRigidClaims(Turn& t) {
#if PSC_HAS_RIGID
    PSC_UNROLL_STATE for (int i = 0; i < kLayers * 5; ++i) t.rigidGroup[i] = Board::zero();
    PSC_UNROLL_STATE for (int i = 0; i < kLayers; ++i) t.rigidApplied[i] = Board::zero();
#else
    (void)t;
#endif
}

// Where a turn's TurnScratch lies: on its stack, or, for an environment in
// the batch on the GPU, in the batch (UndoStack::scratch), one per nested turn.
#if defined(__CUDA_ARCH__)
constexpr bool kTurnScratchInBatch = kEnvInBatch;
#else
constexpr bool kTurnScratchInBatch = false;
#endif
template <bool InBatch = kTurnScratchInBatch>
struct TurnScratchSlot {
    TurnScratch s;
    PSC_DEVICE PSC_INLINE explicit TurnScratchSlot(UndoStack&) {}
};
template <>
struct TurnScratchSlot<true> {
    UndoStack& u;
    TurnScratch& s;
    PSC_DEVICE PSC_INLINE explicit TurnScratchSlot(UndoStack& undo) : u(undo), s(undo.scratch[undo.scratchDepth++]) {
#if defined(__CUDA_ARCH__)
        // Unreachable by kMaxTurnNesting's argument; past it, stop the
        // kernel rather than write another environment's scratch.
        if (u.scratchDepth > kMaxTurnNesting) __trap();
#endif
    }
    PSC_DEVICE PSC_INLINE ~TurnScratchSlot() { --u.scratchDepth; }
};

// The rules of a turn (the reference's processInput up to its command
// queue): the player's movement, rules, movement resolution with the rigid
// retry loop, late rules.  dir is 0 up, 1 left, 2 down, 3 right, 4 action,
// or -1 for none.  `scratch.bak` receives the level as it was where the
// turn keeps it (keepsLevel).  Returns false when require_player_movement
// undid the turn.
PSC_DEVICE PSC_INLINE bool runRules(Env& e, int dir, TurnScratch& scratch, bool keepsLevel) {
    Snapshot& bak = scratch.bak;
    e.againing = 0;
    if (keepsLevel) saveObjects(e, bak);
    if (kHasDormantGroups) scratch.dormantBefore = e.dormant;
    Board playerPositions = Board::zero();
    if (dir >= 0) {
        const int direction = dir == 0 ? 0 : dir == 1 ? 2 : dir == 2 ? 1 : dir == 3 ? 3 : 4;  // field bit
        playerPositions = playerCells(e);
        addPlayerMovement(e, playerPositions, direction);
    }
    Turn& t = scratch.turn;
    t.banned = 0;
    t.dormantGroupMatched = 0;
    clearRigidClaims(t);
    e.queue = 0;

#if PSC_HAS_RIGID
    // A retry starts from the objects in bak (the player's movement changed
    // only movements) and these movements.
    Board* startMov = scratch.startMov;
    PSC_UNROLL_STATE for (int L = 0; L < kLayers; ++L) {
        if (!layerCanMove(L)) continue;
        PSC_UNROLL for (int k = 0; k < 5; ++k) startMov[5 * L + k] = e.mov[5 * L + k];
    }
    for (int iteration = 1;; ++iteration) {
        applyEarlyRules(e, t);
        if (!resolveMovements(e, t)) {
            applyLateRules(e, t);
            break;
        }
        // A rigid group was banned: start over without it (at most 50 tries).
        loadObjects(e, bak);
        PSC_UNROLL_STATE for (int L = 0; L < kLayers; ++L) {
            if (!layerCanMove(L)) continue;
            PSC_UNROLL for (int k = 0; k < 5; ++k) e.mov[5 * L + k] = startMov[5 * L + k];
        }
        clearRigidClaims(t);
        e.queue = 0;
        if (iteration >= 50) break;
    }
#else
    applyEarlyRules(e, t);
    resolveMovements(e, t);
    applyLateRules(e, t);
#endif
    // No group that can go dormant matched (or all were skipped already):
    // none can match again until the level is replaced.
    if (kHasDormantGroups && !t.dormantGroupMatched) e.dormant = 1;

    if (kRequirePlayerMovement && playerPositions.any()) {
        // Some player moved: one of its starting cells holds no player object now.
        if (!andNot(playerPositions, playerObjects(e)).any()) {
            restoreTurnStart(e, scratch);
            e.textMode = 0;
            return false;
        }
    }
    return true;
}

// Whether one of `kCommands` is queued this turn.  A turn looks only for the
// commands a rule of the game can queue (kHasCancelCommand,
// kHasRestartCommand, kHasCheckpoint, kHasAgainCommand): a game without
// `again` compiles no dry run, one without `cancel`, `restart` or
// `checkpoint` no test for them.
template <u32 kCommands>
PSC_DEVICE PSC_INLINE bool queued(const Env& e) {
    constexpr u32 kUnqueueable = (kHasCancelCommand ? 0u : u32{kCmdCancel}) | (kHasRestartCommand ? 0u : u32{kCmdRestart}) |
                                 (kHasCheckpoint ? 0u : u32{kCmdCheckpoint}) | (kHasAgainCommand ? 0u : u32{kCmdAgain});
    constexpr u32 kLooked = kCommands & ~kUnqueueable;
    if constexpr (kLooked == 0) return false;
    else return (e.queue & kLooked) != 0;
}

// The command queue of the `again` dry run (processInput with dontDoWin and
// dontModify), whose rules `changed` the level or not: it never keeps a
// change; returns whether another turn would change the level.
PSC_DEVICE PSC_INLINE bool dryRunCommands(Env& e, UndoStack& u, const TurnScratch& scratch, bool changed) {
    const Snapshot& bak = scratch.bak;
    if (queued<kCmdCancel>(e)) {
        const bool commandsLeft = popcount(e.queue) > 1;
        restoreTurnStart(e, scratch);
        return commandsLeft;
    }
    if (queued<kCmdRestart>(e)) pushUndo(u, bak);
    if (changed) {
        restoreTurnStart(e, scratch);
        return true;
    }
    if (queued<kCmdWin | kCmdRestart>(e)) return true;
    if (queued<kCmdCheckpoint>(e)) saveObjects(e, e.restartTarget);
    e.queue = 0;
    return false;
}

// Turns of an `again` chain run within one input; a chain that never ends
// (an animation loop) is cut off here.
inline constexpr int kMaxAgainTurns = 10000;

// The clock of psc_expand's deadlines (psc_set_deadline), in nanoseconds:
// the host's steady clock on the CPU (runtime/plugin_host/ExpandDeadline.h),
// the GPU's global timer on the GPU (the host puts the deadline on it).
#if !defined(__CUDACC__)
}  // namespace psc_game
namespace psc_host {
int64_t steadyNanoseconds();
}  // namespace psc_host
namespace psc_game {
inline unsigned long long deadlineClock() { return static_cast<unsigned long long>(psc_host::steadyNanoseconds()); }
#else
PSC_DEVICE PSC_INLINE unsigned long long deadlineClock() {
    unsigned long long t;
    asm volatile("mov.u64 %0, %%globaltimer;" : "=l"(t));
    return t;
}
#endif
// Whether a deadline on deadlineClock (0: none) has passed.
PSC_DEVICE PSC_INLINE bool deadlinePassed(unsigned long long deadline) { return deadline && deadlineClock() >= deadline; }
// An again chain stops at the expansion's deadline (UndoStack::deadline), checked every 16 turns.
PSC_DEVICE PSC_INLINE bool chainPastDeadline(const UndoStack& u, int turns) {
    return (turns & 15) == 15 && deadlinePassed(u.deadline);
}

// psc_again_mode: a step settles its `again` chain (the reference's test
// harness), or runs one turn and leaves the next for a later step (its player,
// which draws each turn).
enum AgainMode { kAgainSettle = 0, kAgainOneTurn = 1 };

// An input's again chain ends, settled, before the again turn due: a turn a
// step leaves it to the next step, and an episode that stops on a win ends.
PSC_DEVICE PSC_INLINE bool chainEndsHere(const Env& e) { return e.againMode == kAgainOneTurn || (e.stopOnWin && e.wins); }
// The chain is cut off after `turns` turns: too long, or past the deadline.
PSC_DEVICE PSC_INLINE bool chainCutOff(const UndoStack& u, int turns) {
    return turns >= kMaxAgainTurns || chainPastDeadline(u, turns);
}

// An again turn repeats its dry run exactly where nothing but the level
// decides what rules do: no random stream (which the dry run advanced) and no
// movements left between turns (which restoring the level clears).
constexpr bool kDryRunRepeatsTurn = !PSC_USES_RANDOM && !kMovementsCanLinger;

// Whether an input's again chain keeps its dry run's result as the again
// turn that follows, instead of undoing it and playing the turn: the dry run
// changed the level and queued neither cancel nor restart (the again turn
// plays on from it), and playInput would run that turn (the chain settles
// within the input and is not cut off after againTurns turns).
PSC_DEVICE PSC_INLINE bool keepsDryRun(const Env& e, const UndoStack& u, bool changed, int againTurns) {
    if (!kDryRunRepeatsTurn || !changed || queued<kCmdCancel | kCmdRestart>(e)) return false;
    return !chainEndsHere(e) && !chainCutOff(u, againTurns);
}

// What a turn needs the level as it found it for, whatever its input: a
// cancel or the again dry run restores it, require_player_movement too, a
// restart command's undo entry is it, the rigid retry starts from it.  Beyond
// these only an input's undo entry does, so a turn of a game without them,
// with no undo history (psc_batch_options.undo_depth 0, the default), neither
// copies the level nor compares it with the copy.
constexpr bool kTurnMayRestoreLevel =
    kHasCancelCommand || kHasAgainCommand || kRequirePlayerMovement || kHasRestartCommand || PSC_HAS_RIGID;

// A whole turn (the reference's processInput and processCommandQueue, with
// dontModify false): the rules, then cancel, restart, undo history, the win
// check, checkpoint, and the dry run that decides whether `again` follows.
// The dry run goes round the same loop, so the rules are compiled once.
// Compiled in the turn's unit (PSC_DEFINES_TURN), declared for all.
//
// Within an input's again chain (againTurns, playInput's count of its
// turns; null elsewhere), a dry run whose rules changed the level becomes the
// again turn it foretells (keepsDryRun), which the chain would run next from
// the same level with the same rules.  Commands no rule of the game queues
// are not looked for (queued).
PSC_DEVICE PSC_TURN void playTurn(Env& e, UndoStack& u, int dir, bool dontDoWin, int* againTurns);
#if PSC_DEFINES_TURN
PSC_DEVICE PSC_TURN void playTurn(Env& e, UndoStack& u, int dir, bool dontDoWin, int* againTurns) {
    PSC_ON_STACK(e);
    bool dryRun = false;
    for (;;) {
        TurnScratchSlot<> scratch(u);
        const Snapshot& bak = scratch.s.bak;
        const bool keepsLevel = kTurnMayRestoreLevel || (dir != -1 && u.capacity > 0);
        const bool ruled = runRules(e, dir, scratch.s, keepsLevel);
        if (dryRun) {
            const bool changed = ruled && !sameObjects(e, bak);
            if (!ruled || !againTurns || !keepsDryRun(e, u, changed, *againTurns)) {
                if (ruled && dryRunCommands(e, u, scratch.s, changed)) e.againing = 1;
                e.queue = 0;
                return;
            }
            ++*againTurns;
        }
        if (!ruled) return;
        noteShownMessage(e);
        if (queued<kCmdCancel>(e)) {
            restoreTurnStart(e, scratch.s);
            return;
        }
        if (queued<kCmdRestart>(e)) {
            pushUndo(u, bak);
            // Where the restart runs no level-start turn and no again turn
            // or restart is under way, it only puts the restart target back:
            // done here, it spares the state in registers the trip through
            // memory that outOfLine takes (slidings restarts every few turns).
            if (!kRunRulesOnLevelStart && !e.againing && !e.restarting) restoreLevel(e, e.restartTarget);
            else outOfLine(e, u, [](Env& m, UndoStack& mu) { doRestart(m, mu, true); });
        }
        // A dry run kept has changed the level; without a copy, nothing asks.
        const bool modified = dryRun || (keepsLevel && !sameObjects(e, bak));
        if (modified && dir != -1) pushUndo(u, bak);
        if (!e.textMode) checkWin(e, u, dontDoWin);
        if (queued<kCmdCheckpoint>(e)) saveObjects(e, e.restartTarget);
        if (!(queued<kCmdAgain>(e) && modified)) break;
        dryRun = true;
        dir = -1;
    }
    e.queue = 0;
}
#endif

PSC_DEVICE PSC_COLD void coldTurn(Env& e, UndoStack& u, bool dontDoWin) { playTurn(e, u, -1, dontDoWin, nullptr); }

// ---- inputs, as the reference's test harness gives them

enum Input { kInputUp = 0, kInputLeft, kInputDown, kInputRight, kInputAction, kInputUndo, kInputRestart, kInputTick };
inline constexpr int kInputCount = 8;

// The undo and restart inputs' own work, before the turns of their `again`
// chains (playInput).
PSC_DEVICE PSC_COLD void undoOrRestart(Env& e, UndoStack& u, int input) {
    if (input == kInputUndo) doUndo(e, u, false, true);
    else doRestart(e, u, false);
}

// One input's turns, and every `again` turn they trigger (they settle within
// the input, unless the again mode is one turn per step), after
// undoOrRestart for the undo and restart inputs.  Returns false when an
// again chain had to be cut off.
PSC_DEVICE PSC_INPUT bool playInput(Env& e, UndoStack& u, int input) {
    bool play = input != kInputUndo && input != kInputRestart;
    int dir = input <= kInputAction ? input : -1;
    if (play && e.againing) {
        // An again turn is pending (one turn per step): it runs, and the input
        // is dropped, as the reference's player drops keys during a chain.
        e.againing = 0;
        dir = -1;
    }
    for (int turns = 0;; ++turns) {
        if (play) playTurn(e, u, dir, false, &turns);
        if (!e.againing || chainEndsHere(e)) return true;
        if (chainCutOff(u, turns)) {
            e.againing = 0;
            return false;
        }
        e.againing = 0;
        play = true;
        dir = -1;
    }
}

// One input: undoOrRestart where it applies, then playInput.
PSC_DEVICE PSC_INPUT bool applyInput(Env& e, UndoStack& u, int input) {
    if (input == kInputUndo || input == kInputRestart) {
        outOfLine(e, u, [input](Env& m, UndoStack& mu) { undoOrRestart(m, mu, input); });
    }
    return playInput(e, u, input);
}

// Settles an `again` chain started outside applyInput (by a level start).
PSC_DEVICE PSC_COLD bool settle(Env& e, UndoStack& u) {
    for (int n = 0; e.againing && !(e.stopOnWin && e.wins); ++n) {
        if (n >= kMaxAgainTurns) {
            e.againing = 0;
            return false;
        }
        e.againing = 0;
        coldTurn(e, u, false);
    }
    return true;
}

// Starts entry `entry` as the harness does after compiling (the level seed
// must be set first).
PSC_DEVICE PSC_COLD bool startAtEntry(Env& e, UndoStack& u, int entry) {
    e.entry = static_cast<short>(entry);
    e.titleScreen = 0;
    e.textMode = 0;
    e.againing = 0;
    e.restarting = 0;
    e.dormant = 0;
    e.queue = 0;
    e.wins = 0;
    e.startExisted = entry >= 0 && entry < kEntries;
    clearUndo(u);
    if (!e.startExisted || kEntryIsMessage[entry]) {
        // No level buffer yet: an empty one.
        e.width = 0;
        e.height = 0;
        e.rowStart = Board::zero();
        e.inside = Board::zero();
        for (int o = 0; o < kObjects; ++o) e.obj[o] = Board::zero();
        for (int m = 0; m < kLayers * 5; ++m) e.mov[m] = Board::zero();
        saveObjects(e, e.restartTarget);
    }
    loadEntry(e, u);
    return !(kRunRulesOnLevelStart && e.againing) || settle(e, u);
}

PSC_DEVICE PSC_INLINE Screen screenOf(const Env& e) {
    return e.titleScreen ? kScreenTitle : e.textMode ? kScreenMessage : kScreenLevel;
}

// Device pointers of a CUDA batch, passed by value to every kernel.
struct DeviceBatch {
    Env* envs;
    Snapshot* undoEntries;  // [numEnvs][undoDepth]
    int* undoCount;
    int* undoHead;
    int undoDepth;
    int numEnvs;
    int* actions;
    u8* observations;
    float* rewards;
    u8* terminated;
    u8* truncated;
    u8* won;
    int* episodeSteps;
    const int* channelObjects;
    int channels;
    int maxWidth;
    int maxHeight;
    unsigned long long* stats;  // steps, wins, episodes, invalid actions (psc_run_kernel)
    TurnScratch* turnScratch;   // [numEnvs][kMaxTurnNesting] where kEnvInBatch, else null
};

// ---- episodes (the plugin's step, shared by the CPU and CUDA backends)

enum AutoReset { kAutoResetOff = 0, kAutoResetSameStep = 1, kAutoResetNextStep = 2 };

struct StepOutcome {
    float reward;
    u8 terminated;
    u8 truncated;
    u8 won;
    u8 cutOff;
    u8 againing;  // an again turn is pending (one turn per step)
    short message;  // kRuleMessages index shown by the step, or -1
};

PSC_DEVICE PSC_COLD void startEpisode(Env& e, UndoStack& u) {
    e.stopOnWin = e.autoReset != kAutoResetOff ? 1 : 0;
    e.unavailable = 0;
    e.startCutOff = startAtEntry(e, u, e.levelEntry) ? 0 : 1;
    e.startWon = e.wins > 0 ? 1 : 0;
    e.episodeSteps = 0;
    e.needsReset = 0;
}

#if PSC_DEFINES_LEVEL_CHANGES
PSC_DEVICE PSC_LEVEL_CHANGE void stepEvent(Env& e, UndoStack& u, bool newEpisode, int action) {
    PSC_ON_STACK(e);
    if (newEpisode) startEpisode(e, u);
    else undoOrRestart(e, u, action);
}
#endif

// One step: the input, and the auto-reset it may need.  Everything it runs
// out of line goes through one call of outOfLine: with the state in
// registers each call stores and reloads the environment, code that NVVM and
// ptxas pay for at every call (without any, dictionary's NVRTC time was a
// quarter shorter).
PSC_DEVICE PSC_INPUT StepOutcome stepEnvironment(Env& e, UndoStack& u, int action) {
    StepOutcome out = {0.0f, 0, 0, 0, 0, 0, -1};
    clearShownMessage(e);
    // A next-step auto-reset is the whole step.
    bool played = e.needsReset;
    bool newEpisode = e.needsReset;
    bool event = newEpisode || action == kInputUndo || action == kInputRestart;
    if (!newEpisode) e.wins = 0;
    for (;;) {
        if (event) outOfLine(e, u, [newEpisode, action](Env& m, UndoStack& mu) { stepEvent(m, mu, newEpisode, action); });
        if (played) return out;
        played = true;
        const bool settled = playInput(e, u, action);
        out.won = e.wins > 0;
        out.reward = static_cast<float>(e.wins);
        out.cutOff = !settled || e.unavailable;
        out.againing = e.againing;
        out.message = static_cast<short>(shownMessageOf(e));
        ++e.episodeSteps;
        if (e.autoReset == kAutoResetOff) {
            out.terminated = e.titleScreen && e.startExisted;
            return out;
        }
        out.terminated = out.won;
        out.truncated = !out.won && e.maxEpisodeSteps > 0 && e.episodeSteps >= e.maxEpisodeSteps;
        if (!(out.terminated || out.truncated)) return out;
        if (e.autoReset != kAutoResetSameStep) {
            e.needsReset = 1;
            return out;
        }
        event = true;
        newEpisode = true;
    }
}

// Multi-hot object planes: out[(c * maxHeight + y) * maxWidth + x].
PSC_DEVICE PSC_COLD void observeEnvironment(const Env& e, const int* channelObjects, int channels, int maxWidth,
                                            int maxHeight, u8* out) {
    for (int i = 0; i < channels * maxWidth * maxHeight; ++i) out[i] = 0;
    for (int c = 0; c < channels; ++c) {
        const Board& board = e.obj[channelObjects[c]];
        for (int x = 0; x < e.width && x < maxWidth; ++x) {
            for (int y = 0; y < e.height && y < maxHeight; ++y) {
                out[(c * maxHeight + y) * maxWidth + x] = board.test(positionOf(e, x, y));
            }
        }
    }
}

// A counter-based random action: the same (seed, env, step) gives the same action on every backend.
PSC_DEVICE PSC_INLINE int randomAction(u64 seed, u64 env, u64 step, int count) {
    u64 z = seed ^ (env * 0x9E3779B97F4A7C15ull) ^ (step * 0xD1B54A32D192ED03ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return static_cast<int>((z >> 32) % static_cast<u64>(count));
}

}  // namespace psc_game
