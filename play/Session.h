// One game played through its plugin: an environment that goes from level
// to level, through message screens, as the reference engine does (auto-reset
// off), one turn at a time as its player draws them (`again` turns one by
// one, the messages rules show), with the bookkeeping the player shows: the level's number, the moves
// made, and the inputs that lead from the level's start to where the player
// is (for hints).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "Plugin.h"

namespace psc::play {

enum class Screen { Title, Message, Level };

struct StepReport {
    bool won = false;        // a level was won (the engine has moved on)
    int wonLevel = -1;       // which playable level
    bool completed = false;  // that was the last level: the game is over
    bool cutOff = false;     // an endless `again` chain was cut off
    bool againing = false;   // another `again` turn is due
    std::string message;     // the text of a rule's `message` command shown by this turn, or empty
};

class Session {
public:
    // Random games are seeded with `seed` at every level load, as psc solve's --seed.
    Session(const Plugin& plugin, uint64_t seed);
    ~Session();
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;

    const psc_game_info& info() const { return info_; }
    uint64_t seed() const { return seed_; }

    // Shows LEVELS entry `entry` (a level or a message).
    void startEntry(int entry);
    void startLevel(int level) { startEntry(info_.level_entries[level]); }
    // One turn: an input (psc_action), or, while an `again` turn is due, that
    // turn (then directions and action are dropped, as the reference does).
    StepReport step(int action);
    bool againing() const { return againing_; }

    Screen screen() const { return screen_; }
    int entry() const { return entry_; }
    const std::string& message() const { return message_; }
    // The playable level shown (from 0), or -1 on a message.
    int level() const;
    // The level of an entry, or of the next level after a message; -1 after the last.
    int levelAtOrAfter(int entry) const;
    int width() const { return width_; }
    int height() const { return height_; }
    // Whether cell (x, y) holds channel c's object.
    bool has(int channel, int x, int y) const {
        return observation_[(static_cast<size_t>(channel) * info_.max_height + y) * info_.max_width + x] != 0;
    }

    // Moves since the level's start (undo takes them back, restart clears them).
    int moves() const { return moves_; }
    // The inputs (u l d r x) from the level's start to the state shown, when
    // known: after an undo in a game that uses random, the random stream is
    // not where any sequence of inputs played here would leave it.
    const std::optional<std::string>& path() const { return path_; }

private:
    void refresh();
    std::string key() const;
    void beginLevelBookkeeping();

    const Plugin& plugin_;
    const psc_game_info& info_;
    uint64_t seed_;
    psc_batch* batch_ = nullptr;
    Screen screen_ = Screen::Title;
    int entry_ = 0;
    std::string message_;
    int width_ = 0;
    int height_ = 0;
    std::vector<uint8_t> observation_;
    bool againing_ = false;
    int chainInput_ = -1;  // the input whose `again` chain is running
    int moves_ = 0;
    std::optional<std::string> path_;
    std::string lastKey_;
    std::map<std::string, std::string> pathTo_;  // state key -> the shortest inputs seen that reach it
};

}  // namespace psc::play
