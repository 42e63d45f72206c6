#include "BenchExpand.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <optional>

#include "CudaTimer.h"
#include "StateSpace.h"
#include "StateStore.h"

namespace psc::cli {
namespace {

// Up to `wanted` distinct states, breadth-first from the start (all of them if fewer are reachable).
std::vector<uint64_t> frontier(search::StateSpace& space, size_t wanted) {
    const size_t words = space.keyWords();
    const size_t inputs = space.inputs().size();
    search::StateStore store(words, size_t{8} << 30);
    uint32_t index = 0;
    store.insert(space.root().data(), space.rootHash(), search::StateStore::kNoParent, 0, 0, &index);
    std::vector<uint64_t> children(space.maxBatch() * inputs * words);
    std::vector<uint8_t> flags(space.maxBatch() * inputs);
    std::vector<uint64_t> hashes(space.maxBatch() * inputs);
    std::vector<uint64_t> keys;
    for (size_t next = 0; next < store.size() && store.size() < wanted;) {
        const size_t count = std::min(space.maxBatch(), store.size() - next);
        keys.clear();
        for (size_t i = 0; i < count; ++i) {
            const uint64_t* k = store.key(static_cast<uint32_t>(next + i));
            keys.insert(keys.end(), k, k + words);
        }
        space.expand(keys.data(), count, children.data(), flags.data(), hashes.data());
        for (size_t c = 0; c < count * inputs && store.size() < wanted; ++c) {
            if (flags[c] & (PSC_EXPAND_UNCHANGED | PSC_EXPAND_INVALID)) continue;
            store.insert(&children[c * words], hashes[c], 0, 0, 0, &index);
        }
        next += count;
    }
    std::vector<uint64_t> out;
    out.reserve(wanted * words);
    for (size_t i = 0; i < wanted; ++i) {
        const uint64_t* k = store.key(static_cast<uint32_t>(i % store.size()));
        out.insert(out.end(), k, k + words);
    }
    return out;
}

}  // namespace

int runExpandBench(const BenchOptions& o, const Plugin& plugin, std::optional<CudaTimer>& timer) {
    const bool cuda = o.backend == "cuda";
    std::vector<int> batches = o.batches;
    if (batches.empty()) batches = cuda ? std::vector<int>{1024, 16384, 262144, 1048576} : std::vector<int>{4096};
    const size_t largest = static_cast<size_t>(*std::max_element(batches.begin(), batches.end()));
    try {
        search::SpaceOptions so;
        so.backend = cuda ? search::Backend::Cuda : search::Backend::Cpu;
        so.threads = o.threads;
        so.device = o.device;
        so.maxBatch = largest;
        search::StateSpace space(plugin, so, o.level, "");
        const std::vector<uint64_t> keys = frontier(space, largest);
        const size_t inputs = space.inputs().size();
        fmt::print("{:>10} {:>20} {:>20} {:>20}\n", "batch", "median children/s", "min children/s", "max children/s");
        double best = 0;
        int bestBatch = 0;
        for (int n : batches) {
            space.stage(keys.data(), static_cast<size_t>(n));
            auto run = [&](int calls) {
                if (cuda) {
                    space.synchronize();
                    timer->start();
                    for (int c = 0; c < calls; ++c) space.expandStaged(static_cast<size_t>(n));
                    const double ms = timer->stop();
                    space.synchronize();  // reports expansion errors
                    return ms / 1000.0;
                }
                const auto start = std::chrono::steady_clock::now();
                for (int c = 0; c < calls; ++c) space.expandStaged(static_cast<size_t>(n));
                return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            };
            int calls = 1;
            for (double seconds = run(calls); seconds < 0.1 && calls < (1 << 16); seconds = run(calls)) calls *= 2;
            for (int w = 0; w < o.warmup; ++w) run(calls);
            std::vector<double> rates;
            for (int r = 0; r < o.repeats; ++r) rates.push_back(static_cast<double>(n) * inputs * calls / run(calls));
            std::sort(rates.begin(), rates.end());
            const double median = rates[rates.size() / 2];
            fmt::print("{:>10} {:>20.0f} {:>20.0f} {:>20.0f}\n", n, median, rates.front(), rates.back());
            if (median > best) {
                best = median;
                bestBatch = n;
            }
        }
        fmt::print("game {} level {} backend {}{}; {} inputs a state, {}-byte keys; best batch {}\n", o.gamePath, o.level,
                   o.backend, cuda ? "" : fmt::format(" threads {}", o.threads), inputs, space.keyWords() * 8, bestBatch);
        fmt::print("children/s: {:.0f}\n", best);
    } catch (const std::exception& e) {
        fmt::print(stderr, "psc bench: {}\n", e.what());
        return 2;
    }
    return 0;
}

}  // namespace psc::cli
