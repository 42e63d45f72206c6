// ---- psc template: the turn ----------------------------------------------
// The reference engine's turn and the harness around it, over the game's
// generated rules: player movement, rule groups, movement resolution, the
// rigid-body retry loop, late rules, require_player_movement, the command
// queue (cancel, restart, win, checkpoint, again with its dry run), undo,
// restart and level changes.  Names follow the reference where they help
// compare (processInput, processCommandQueue, doUndo, doRestart, nextLevel).

namespace psc_game {

PSC_DEVICE bool processInput(Env& e, UndoStack& u, int dir, bool dontDoWin, bool dontModify);

PSC_DEVICE PSC_INLINE void saveObjects(const Env& e, Snapshot& s) {
    for (int o = 0; o < kObjects; ++o) s.obj[o] = e.obj[o];
}
PSC_DEVICE PSC_INLINE void loadObjects(Env& e, const Snapshot& s) {
    for (int o = 0; o < kObjects; ++o) e.obj[o] = s.obj[o];
}
PSC_DEVICE PSC_INLINE bool sameObjects(const Env& e, const Snapshot& s) {
    for (int o = 0; o < kObjects; ++o) {
        if (!(e.obj[o] == s.obj[o])) return false;
    }
    return true;
}

// ---- undo history (a ring: when full, the oldest entry is dropped)

PSC_DEVICE PSC_INLINE void pushUndo(UndoStack& u, const Snapshot& s) {
    if (u.capacity == 0) return;
    if (u.count == u.capacity) {
        u.head = (u.head + 1) % u.capacity;
        --u.count;
    }
    u.entries[(u.head + u.count) % u.capacity] = s;
    ++u.count;
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
PSC_DEVICE void clearMovementsAfterRestore(Env& e) {
    if (!kMovementsCanLinger) {
        for (int m = 0; m < kLayers * 5; ++m) e.mov[m] = Board::zero();
        return;
    }
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

PSC_DEVICE void restoreLevel(Env& e, const Snapshot& s) {
    loadObjects(e, s);
    clearMovementsAfterRestore(e);
    e.againing = 0;
    e.queue = 0;
}

PSC_DEVICE void doUndo(Env& e, UndoStack& u, bool force, bool ignoreDuplicates) {
    if (kNoUndo && !force) return;
    if (ignoreDuplicates) {
        while (u.count > 0 && sameObjects(e, topUndo(u))) --u.count;
    }
    if (u.count > 0) {
        const Snapshot s = topUndo(u);
        restoreLevel(e, s);
        --u.count;
    }
}

PSC_DEVICE void doRestart(Env& e, UndoStack& u, bool force) {
    if (e.restarting) return;
    if (!force && kNoRestart) return;
    if (e.againing) doUndo(e, u, force, true);
    e.restarting = 1;
    if (!force) {
        Snapshot s;
        saveObjects(e, s);
        pushUndo(u, s);
    }
    const Snapshot target = e.restartTarget;
    restoreLevel(e, target);
    if (kRunRulesOnLevelStart) processInput(e, u, -1, true, false);
    e.queue = 0;
    e.restarting = 0;
}

// ---- levels

PSC_DEVICE void goToTitleScreen(Env& e) {
    e.againing = 0;
    e.titleScreen = 1;
    e.textMode = 1;
}

// Loads entry e.entry: a level replaces the buffer; a message only shows.
// Either way the random stream restarts from the level seed.
PSC_DEVICE void loadEntry(Env& e, UndoStack& u) {
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
    e.queue = 0;
    clearUndo(u);
    saveObjects(e, e.restartTarget);
    if (kRunRulesOnLevelStart) processInput(e, u, -1, true, false);
}

PSC_DEVICE void nextLevel(Env& e, UndoStack& u) {
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

PSC_DEVICE void checkWin(Env& e, UndoStack& u, bool dontDoWin) {
    bool won = (e.queue & kCmdWin) != 0;
    if (!won) {
        if (kWinConditionCount == 0) return;
        won = winConditionsHold(e);
    }
    if (won && !dontDoWin) {
        e.againing = 0;
        ++e.wins;
        if (!e.stopOnWin) nextLevel(e, u);
    }
}

// ---- the turn

PSC_DEVICE PSC_INLINE u32 queueCommands(u32 queue, u32 commands) {
    if (commands == 0 || (queue & kCmdCancel)) return queue;
    if ((queue & kCmdRestart) && !(commands & kCmdCancel)) return queue;
    if (commands & (kCmdCancel | kCmdRestart)) queue = 0;
    return queue | commands;
}

PSC_DEVICE bool processCommandQueue(Env& e, UndoStack& u, const Snapshot& bak, bool dontModify, bool dontDoWin,
                                    int inputDir) {
    if (e.queue & kCmdCancel) {
        const bool commandsLeft = popcount(e.queue) > 1;
        restoreLevel(e, bak);
        return commandsLeft;
    }
    if (e.queue & kCmdRestart) {
        pushUndo(u, bak);
        if (!dontModify) doRestart(e, u, true);
    }
    const bool modified = !sameObjects(e, bak);
    if (modified) {
        if (dontModify) {
            restoreLevel(e, bak);
            return true;
        }
        if (inputDir != -1) pushUndo(u, bak);
    }
    if (dontModify && (e.queue & (kCmdWin | kCmdRestart))) return true;
    if (!e.textMode) checkWin(e, u, dontDoWin);
    if (e.queue & kCmdCheckpoint) saveObjects(e, e.restartTarget);
    if ((e.queue & kCmdAgain) && modified) {
        if (processInput(e, u, -1, true, true)) e.againing = 1;
    }
    e.queue = 0;
    return modified;
}

PSC_DEVICE PSC_INLINE void clearRigidClaims(Turn& t) {
#if PSC_HAS_RIGID
    for (int i = 0; i < kLayers * 5; ++i) t.rigidGroup[i] = Board::zero();
    for (int i = 0; i < kLayers; ++i) t.rigidApplied[i] = Board::zero();
#else
    (void)t;
#endif
}

// One turn: dir is 0 up, 1 left, 2 down, 3 right, 4 action, or -1 for none.
PSC_DEVICE bool processInput(Env& e, UndoStack& u, int dir, bool dontDoWin, bool dontModify) {
    e.againing = 0;
    Snapshot bak;
    saveObjects(e, bak);
    Board playerPositions = Board::zero();
    if (dir >= 0) {
        const int direction = dir == 0 ? 0 : dir == 1 ? 2 : dir == 2 ? 1 : dir == 3 ? 3 : 4;  // field bit
        playerPositions = playerCells(e);
        addPlayerMovement(e, playerPositions, direction);
    }
    Turn t;
    t.banned = 0;
    clearRigidClaims(t);
    e.queue = 0;

    Board startObj[kObjects];
    Board startMov[kLayers * 5];
    for (int o = 0; o < kObjects; ++o) startObj[o] = e.obj[o];
    for (int m = 0; m < kLayers * 5; ++m) startMov[m] = e.mov[m];

    int iteration = 0;
    bool rigidLoop;
    do {
        rigidLoop = false;
        ++iteration;
        applyEarlyRules(e, t);
        if (resolveMovements(e, t)) {
            rigidLoop = true;
            for (int o = 0; o < kObjects; ++o) e.obj[o] = startObj[o];
            for (int m = 0; m < kLayers * 5; ++m) e.mov[m] = startMov[m];
            clearRigidClaims(t);
            e.queue = 0;
        } else {
            applyLateRules(e, t);
        }
    } while (iteration < 50 && rigidLoop);

    if (kRequirePlayerMovement && playerPositions.any()) {
        // Some player moved: one of its starting cells holds no player object now.
        if (!andNot(playerPositions, playerObjects(e)).any()) {
            restoreLevel(e, bak);
            e.textMode = 0;
            return false;
        }
    }
    return processCommandQueue(e, u, bak, dontModify, dontDoWin, dir);
}

// ---- inputs, as the reference's test harness gives them

enum Input { kInputUp = 0, kInputLeft, kInputDown, kInputRight, kInputAction, kInputUndo, kInputRestart, kInputTick };
inline constexpr int kInputCount = 8;

// Turns of an `again` chain run within one input; a chain that never ends
// (an animation loop) is cut off here.
inline constexpr int kMaxAgainTurns = 10000;

// Returns false when an again chain had to be cut off.
PSC_DEVICE bool settle(Env& e, UndoStack& u) {
    for (int n = 0; e.againing && !(e.stopOnWin && e.wins); ++n) {
        if (n >= kMaxAgainTurns) {
            e.againing = 0;
            return false;
        }
        e.againing = 0;
        processInput(e, u, -1, false, false);
    }
    return true;
}

PSC_DEVICE bool applyInput(Env& e, UndoStack& u, int input) {
    switch (input) {
        case kInputUndo: doUndo(e, u, false, true); break;
        case kInputRestart: doRestart(e, u, false); break;
        case kInputTick: processInput(e, u, -1, false, false); break;
        default: processInput(e, u, input, false, false); break;
    }
    return settle(e, u);
}

// Starts entry `entry` as the harness does after compiling (the level seed
// must be set first).
PSC_DEVICE bool startAtEntry(Env& e, UndoStack& u, int entry) {
    e.entry = static_cast<short>(entry);
    e.titleScreen = 0;
    e.textMode = 0;
    e.againing = 0;
    e.restarting = 0;
    e.queue = 0;
    e.wins = 0;
    e.startExisted = entry >= 0 && entry < kEntries;
    clearUndo(u);
    if (!e.startExisted || kEntryIsMessage[entry]) {
        // No level buffer yet: an empty one.
        e.width = 0;
        e.height = 0;
        for (int o = 0; o < kObjects; ++o) e.obj[o] = Board::zero();
        for (int m = 0; m < kLayers * 5; ++m) e.mov[m] = Board::zero();
        e.inside = Board::zero();
        e.rowStart = Board::zero();
        saveObjects(e, e.restartTarget);
    }
    loadEntry(e, u);
    return settle(e, u);
}

PSC_DEVICE PSC_INLINE Screen screenOf(const Env& e) {
    return e.titleScreen ? kScreenTitle : e.textMode ? kScreenMessage : kScreenLevel;
}

}  // namespace psc_game
