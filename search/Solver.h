// psc's solver: solutions of a level found by search over a game's plugin
// (batched expansion of state keys, on CPU threads or the GPU).
//   bfs       breadth-first: the shortest solution in inputs (the default);
//   astar     best-first on f = g + h, h the win-condition estimate
//             (psc_estimate_distance; not a lower bound in general, so
//             solutions may be longer than the shortest);
//   wastar    weighted A* (f = g + w h), for levels breadth-first cannot finish;
//   greedy    greedy best-first (f = h, ties to the shallower);
//   beam      breadth-first keeping the best `beamWidth` new states a layer
//             (by h; by default widening while beams empty): deep solutions
//             in bounded memory, incomplete;
//   portfolio on the CPU breadth-first for 1/25 of the time, greedy until
//             three quarters of it, beam until seven eighths, then weighted
//             A*; on the GPU breadth-first for 1/10, beam until half the
//             time, greedy until seven eighths, then weighted A*.
// docs/search.md gives the measurements behind these choices.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "Plugin.h"
#include "StateSpace.h"

namespace psc::search {

enum class Algorithm { BreadthFirst, AStar, WeightedAStar, Greedy, Beam, Portfolio };
std::optional<Algorithm> parseAlgorithm(std::string_view name);
std::string_view algorithmName(Algorithm algorithm);

// solved: a solution; exhausted: every reachable state seen, none won; limit: a limit stopped the search.
enum class Status { Solved, Exhausted, Limit };
std::string_view statusName(Status status);

struct Progress {
    std::string_view stage;   // the search running: "bfs", "greedy", "beam 4096" (its width)...
    int depth = 0;            // breadth-first: the layer; best-first: the deepest state expanded
    uint64_t expanded = 0;
    uint64_t unique = 0;
    double seconds = 0;       // since this search (a portfolio's stage, a beam's width) began
    size_t bytes = 0;         // the state store's memory
};

struct SolveOptions {
    Algorithm algorithm = Algorithm::BreadthFirst;
    double timeLimit = 60;    // seconds
    uint64_t maxStates = 0;   // unique states; 0: only memory bounds them
    size_t maxMemory = 0;     // bytes for the state store; 0: half of the machine's memory (on the GPU, nine tenths of its free memory)
    double weight = 2;        // wastar's w
    uint64_t beamWidth = 0;   // states a beam layer keeps; 0: widening from 256 to 10,000 on the CPU, 4,096 to 1,048,576 on the GPU
    SpaceOptions space;
    std::string fromInputs;   // inputs played from the level's start before searching
    std::function<void(const Progress&)> progress;  // called about once a second
};

struct SolveResult {
    Status status = Status::Limit;
    std::string solution;     // letters u d l r x, when solved
    std::string limit;        // which limit stopped the search: time, states, memory, or beam (the beam emptied after dropping states)
    uint64_t expanded = 0;    // states whose children were computed
    uint64_t generated = 0;   // children computed
    uint64_t unique = 0;      // distinct states reached
    double seconds = 0;
    size_t bytes = 0;         // peak memory of the state store
    // The level's start ran an `again` chain that never settles (cut off after
    // 10,000 turns): the reference engine never takes an input there, so
    // there is nothing to search and the status is exhausted.
    bool startCutOff = false;
    // The level's start won it (a run_rules_on_level_start turn's `again`
    // chain did): solved by no input, nothing searched.
    bool startWon = false;
};

// Throws std::runtime_error on a bad level, input letter or plugin failure.
SolveResult solve(const Plugin& plugin, int level, const SolveOptions& options);

}  // namespace psc::search
