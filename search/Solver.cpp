#include "Solver.h"

#include <algorithm>
#include <stdexcept>
#include <utility>
#include <vector>

#include "SearchRun.h"

namespace psc::search {

std::optional<Algorithm> parseAlgorithm(std::string_view name) {
    if (name == "bfs") return Algorithm::BreadthFirst;
    if (name == "astar") return Algorithm::AStar;
    if (name == "wastar") return Algorithm::WeightedAStar;
    if (name == "greedy") return Algorithm::Greedy;
    if (name == "beam") return Algorithm::Beam;
    if (name == "portfolio") return Algorithm::Portfolio;
    return std::nullopt;
}

std::string_view algorithmName(Algorithm algorithm) {
    switch (algorithm) {
        case Algorithm::BreadthFirst: return "bfs";
        case Algorithm::AStar: return "astar";
        case Algorithm::WeightedAStar: return "wastar";
        case Algorithm::Greedy: return "greedy";
        case Algorithm::Beam: return "beam";
        case Algorithm::Portfolio: return "portfolio";
    }
    return "?";
}

std::string_view statusName(Status status) {
    switch (status) {
        case Status::Solved: return "solved";
        case Status::Exhausted: return "exhausted";
        case Status::Limit: return "limit";
    }
    return "?";
}

namespace {

// Adds one search's counts to a sequence's; its outcome becomes the sequence's.
void accumulate(SolveResult& total, const SolveResult& r) {
    total.expanded += r.expanded;
    total.generated += r.generated;
    total.unique = std::max(total.unique, r.unique);
    total.seconds += r.seconds;
    total.bytes = std::max(total.bytes, r.bytes);
    total.status = r.status;
    total.solution = r.solution;
    total.limit = r.limit;
}

// The widest default beam: 10,000 states a layer on the CPU, fewer where a
// layer's children (kept on the host until the cut) would pass 1 GB; on the
// GPU, which keeps them on the device, 16,777,216 (4,096 widened six times),
// fewer where they would pass 8 GB.  (Limerick level 9's beams empty up to
// 1,048,576 states wide; one of 4,194,304 solves it in 1.4 s on one H200.)
size_t widestBeam(const StateSpace& space) {
    const bool gpu = space.backend() == Backend::Cuda;
    const size_t width = gpu ? 16777216 : 10000;
    const size_t byMemory = ((gpu ? size_t{8} : size_t{1}) << 30) / (space.keyWords() * 8 * space.inputs().size());
    return std::max<size_t>(1000, std::min(width, byMemory));
}

// Beam search at --beam-width, or by default widening: 256 states a layer
// on the CPU, 4,096 on the GPU, four times wider each time a beam empties
// after dropping states, up to widestBeam().  Narrow beams reach deep
// solutions in milliseconds (the corpus' 250 ms levels), wide ones get past
// misleading estimates.  A GPU's layer takes about as long at 4,096 states as
// at 256 (the batch's launches and the host's reads of its outcome).
SolveResult beam(StateSpace& space, const SolveOptions& options, double timeLimit) {
    const size_t widest = options.beamWidth ? options.beamWidth : widestBeam(space);
    const size_t narrowest = space.backend() == Backend::Cuda ? 4096 : 256;
    SolveResult total;
    for (size_t width = options.beamWidth ? widest : std::min(narrowest, widest);; width = std::min(width * 4, widest)) {
        const double budget = timeLimit - total.seconds;
        if (budget <= 0) break;
        SearchRun run(space, options, budget, "beam " + std::to_string(width));
        accumulate(total, space.backend() == Backend::Cuda ? deviceBeamSearch(run, width) : beamSearch(run, width));
        if (total.status != Status::Limit || total.limit != "beam" || width == widest) break;
    }
    return total;
}

SolveResult runOne(StateSpace& space, const SolveOptions& options, Algorithm algorithm, double timeLimit) {
    if (algorithm == Algorithm::Beam) return beam(space, options, timeLimit);
    const bool hostBreadthFirst = algorithm == Algorithm::BreadthFirst && space.backend() == Backend::Cpu;
    SearchRun run(space, options, timeLimit, std::string(algorithmName(algorithm)),
                  hostBreadthFirst ? StateStore::Keys::Prints : StateStore::Keys::Kept);
    switch (algorithm) {
        case Algorithm::BreadthFirst: return space.backend() == Backend::Cuda ? deviceBreadthFirst(run) : breadthFirst(run);
        case Algorithm::AStar: return bestFirst(run, 1, 1);
        case Algorithm::WeightedAStar: return bestFirst(run, 1, options.weight);
        case Algorithm::Greedy: return bestFirst(run, 0, 1);
        case Algorithm::Beam:
        case Algorithm::Portfolio: break;
    }
    throw std::logic_error("runOne: not one search");
}

// On the CPU, breadth-first for the first 1/25 of the time (the shortest
// solution of a small space), greedy best-first until three quarters of it
// have passed, beam search until seven eighths, then weighted A* with what is
// left (the shares docs/search.md's measurements chose: at 250 ms a level
// greedy solves most, and a restart costs a stage all it had reached; the
// benchmark levels still need beam and weighted A* at 30-60 s).  On the GPU,
// where breadth-first and beam search keep their states on the device and
// run 10-100 times faster than greedy's host-side open list, breadth-first
// gets a tenth and beam search until half the time, before greedy (until
// seven eighths) and weighted A*.  A stage that settles nothing early (a
// beam that empties at its widest, a store that fills) leaves its time to
// the next.  Each stage starts afresh: memory is freed between them.
SolveResult portfolio(StateSpace& space, const SolveOptions& options) {
    using Stages = std::vector<std::pair<Algorithm, double>>;
    const Stages cpu = {{Algorithm::BreadthFirst, 1.0 / 25},
                        {Algorithm::Greedy, 3.0 / 4},
                        {Algorithm::Beam, 7.0 / 8},
                        {Algorithm::WeightedAStar, 1.0}};
    const Stages gpu = {{Algorithm::BreadthFirst, 1.0 / 10},
                        {Algorithm::Beam, 1.0 / 2},
                        {Algorithm::Greedy, 7.0 / 8},
                        {Algorithm::WeightedAStar, 1.0}};
    SolveResult total;
    for (const auto& [algorithm, until] : space.backend() == Backend::Cuda ? gpu : cpu) {
        const double budget = options.timeLimit * until - total.seconds;
        if (budget <= 0) continue;
        const SolveResult r = runOne(space, options, algorithm, budget);
        accumulate(total, r);
        // A search that saw every state settles it; so does a limit on states, which every stage would hit.
        if (r.status != Status::Limit || r.limit == "states") break;
    }
    return total;
}

}  // namespace

SolveResult solve(const Plugin& plugin, int level, const SolveOptions& options) {
    if (!(options.timeLimit > 0)) throw std::runtime_error("the time limit must be positive");
    if (!(options.weight >= 1)) throw std::runtime_error("the weight must be at least 1");
    StateSpace space(plugin, options.space, level, options.fromInputs);
    if (space.rootCutOff()) {
        SolveResult nothing;
        nothing.status = Status::Exhausted;
        nothing.startCutOff = true;
        return nothing;
    }
    if (space.startWon()) {
        SolveResult won;
        won.status = Status::Solved;
        won.unique = 1;
        won.startWon = true;
        return won;
    }
    SolveResult result = options.algorithm == Algorithm::Portfolio
                             ? portfolio(space, options)
                             : runOne(space, options, options.algorithm, options.timeLimit);
    // The plugin is the engine: a solution that does not win when replayed would be a bug in search.
    if (result.status == Status::Solved && !space.rootWon() &&
        !space.winsExactlyAtEnd(options.fromInputs + result.solution)) {
        throw std::runtime_error("internal error: the solution found does not win when replayed");
    }
    return result;
}

}  // namespace psc::search
