// Fuzz target (c): the plugin C ABI driven by random call sequences.
//
// At start-up the target builds the CPU plugins of a few games
// ($PSC_FUZZ_GAMES, colon-separated; default games/sokoban, rigid and ice of
// the source tree) with psc's own pipeline and loads them, or loads the
// plugins $PSC_FUZZ_PLUGINS names.  Each input is a
// program: its first byte picks the plugin, then each operation byte picks an
// ABI call whose arguments come from the bytes after it: batches created with
// any options, resets with any level, seed or entry, steps with any action,
// states saved and loaded through corrupted buffers, dumps into small
// buffers, destroys; and search's calls: state keys encoded, decoded and put
// in search's form, children expanded and distances estimated from keys with
// words and bits changed, deadlines, and the memory psc_expand takes.
//
// The plugins the target builds are compiled by clang with ASan, UBSan and
// coverage, as the target itself, so that a fault inside a game's code is a
// sanitizer report and libFuzzer is guided through the game's rules too;
// plugins named by $PSC_FUZZ_PLUGINS are taken as they are, where faults
// show as crashes (SIGSEGV).  Every buffer handed to the plugin ends at a
// protected page (GuardedBuffer), so a write or read past its size faults at
// once.  A call must return PSC_OK or
// an error code with a message (psc_last_error); anything else aborts, as
// does a broken promise of the search calls: an encoded key that does not
// decode back to itself, a key in search's form that changes when put in it
// again, a child flagged unchanged that differs from its parent, or a child's
// hash that is not its key's.
//
// New ABI functions get an entry in kOperations.
#include <fuzzer/FuzzedDataProvider.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <dlfcn.h>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "Compiler.h"
#include "CppSource.h"
#include "Plugin.h"
#include "PluginBuilder.h"
#include "base/Sha1.h"

namespace {

using psc::Plugin;

// The functions Plugin does not load.
struct ExtraFunctions {
    decltype(&psc_batch_size) batchSize = nullptr;
    decltype(&psc_step_many) stepMany = nullptr;
};

struct LoadedGame {
    std::unique_ptr<Plugin> plugin;
    ExtraFunctions extra;
    std::string name;
};

std::vector<LoadedGame>& games() {
    static std::vector<LoadedGame> loaded;
    return loaded;
}

[[noreturn]] void die(const std::string& message) {
    std::fprintf(stderr, "plugin_abi_fuzzer: %s\n", message.c_str());
    std::abort();
}

std::string readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) die("cannot read " + path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

LoadedGame loadPlugin(const std::string& pluginPath, const std::string& name) {
    std::string error;
    LoadedGame g;
    g.plugin = Plugin::open(pluginPath, &error);
    if (!g.plugin) die(error);
    // A second reference to the library Plugin holds, for the functions it does not load.
    void* handle = dlopen(pluginPath.c_str(), RTLD_NOW | RTLD_NOLOAD);
    if (!handle) die("cannot reopen " + pluginPath);
    g.extra.batchSize = reinterpret_cast<decltype(&psc_batch_size)>(dlsym(handle, "psc_batch_size"));
    g.extra.stepMany = reinterpret_cast<decltype(&psc_step_many)>(dlsym(handle, "psc_step_many"));
    if (!g.extra.batchSize || !g.extra.stepMany) die(pluginPath + " lacks psc_batch_size or psc_step_many");
    g.name = name;
    std::fprintf(stderr, "plugin_abi_fuzzer: %s -> %s\n", name.c_str(), pluginPath.c_str());
    return g;
}

LoadedGame buildGame(const std::string& path) {
    const std::string text = readFile(path);
    psc::CompileResult compiled = psc::compileSource(text);
    if (compiled.status != psc::CompileStatus::Ok) die(path + " does not compile");
    psc::codegen::SourceOptions so;
    so.sourceName = path;
    so.sourceSha1 = psc::sha1Hex(text);
    psc::BuildOptions build;
    build.compiler = "clang++";
    build.optimization = "-O1";
    build.flags = "-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer";
    const psc::BuildResult built = psc::buildCpuPlugin(psc::codegen::cpuPluginSource(*compiled.game, so), build);
    if (!built.ok) die("building the plugin of " + path + " failed:\n" + built.log);
    return loadPlugin(built.pluginPath, path);
}

// Memory that ends at an inaccessible page: the plugin may use exactly
// `size` bytes from data().
class GuardedBuffer {
public:
    explicit GuardedBuffer(size_t size) : size_(size) {
        const size_t page = static_cast<size_t>(sysconf(_SC_PAGESIZE));
        mapped_ = (size + page - 1) / page * page + page;
        void* m = mmap(nullptr, mapped_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (m == MAP_FAILED) die("mmap failed");
        base_ = static_cast<char*>(m);
        mprotect(base_ + mapped_ - page, page, PROT_NONE);
        std::memset(data(), 0xA5, size_);
    }
    // A guarded copy of `bytes`.
    GuardedBuffer(const void* bytes, size_t size) : GuardedBuffer(size) {
        if (size) std::memcpy(data(), bytes, size);
    }
    ~GuardedBuffer() { munmap(base_, mapped_); }
    GuardedBuffer(const GuardedBuffer&) = delete;
    GuardedBuffer& operator=(const GuardedBuffer&) = delete;
    char* data() {
        const size_t page = static_cast<size_t>(sysconf(_SC_PAGESIZE));
        return base_ + mapped_ - page - size_;
    }
    size_t size() const { return size_; }

private:
    size_t size_;
    size_t mapped_ = 0;
    char* base_ = nullptr;
};

// Sizes stay small enough that one input runs in milliseconds.
constexpr int kMaxEnvs = 6;
constexpr int kMaxSteps = 8;

struct Session {
    const LoadedGame& game;
    FuzzedDataProvider& in;
    std::array<psc_batch*, 2> batches{};
    std::array<int32_t, 2> envs{};
    std::vector<char> saved;      // the last saved state
    std::vector<uint64_t> keys;   // the last keys encoded or expanded
    struct Allocation {
        psc_batch* batch;
        void* pointer;
        size_t bytes;
    };
    std::vector<Allocation> allocations;  // psc_device_alloc's, freed before their batch

    const Plugin& p() const { return *game.plugin; }

    // Checks the ABI's promise: PSC_OK or an error code with a message.
    void expectStatus(int status, const char* call) {
        if (status < PSC_OK || status > PSC_ERROR_DEVICE) die(std::string(call) + " returned " + std::to_string(status));
        if (status != PSC_OK) {
            const char* message = p().lastError();
            if (!message || !*message) die(std::string(call) + " failed without a message");
        }
    }

    size_t slot() { return in.ConsumeIntegralInRange<size_t>(0, batches.size() - 1); }
    // A batch, sometimes a null one.
    psc_batch* anyBatch() {
        if (in.ConsumeIntegralInRange<int>(0, 15) == 0) return nullptr;
        return batches[slot()];
    }
    // Usually a valid index below n, sometimes anything.
    int32_t index(int32_t n) {
        switch (in.ConsumeIntegralInRange<int>(0, 7)) {
            case 0: return in.ConsumeIntegral<int32_t>();
            case 1: return n;
            case 2: return -1;
            default: return n > 0 ? in.ConsumeIntegralInRange<int32_t>(0, n - 1) : 0;
        }
    }
    int32_t envCount(psc_batch* b) {
        for (size_t i = 0; i < batches.size(); ++i) {
            if (b && batches[i] == b) return envs[i];
        }
        return 0;
    }
    // A buffer of about `needed` bytes: exact, short, long or empty.
    size_t bufferSize(size_t needed) {
        switch (in.ConsumeIntegralInRange<int>(0, 5)) {
            case 0: return 0;
            case 1: return needed > 0 ? in.ConsumeIntegralInRange<size_t>(0, needed - 1) : 0;
            case 2: return needed + in.ConsumeIntegralInRange<size_t>(1, 64);
            default: return needed;
        }
    }

    void create() {
        const size_t s = slot();
        if (batches[s]) destroy(s);
        psc_batch_options o = psc::defaultBatchOptions();
        if (in.ConsumeIntegralInRange<int>(0, 15) == 0) o.struct_size = in.ConsumeIntegral<uint32_t>();
        o.backend = in.ConsumeIntegralInRange<int>(0, 7) == 0 ? in.ConsumeIntegral<int32_t>() : PSC_BACKEND_CPU;
        o.num_envs = in.ConsumeIntegralInRange<int>(0, 7) == 0 ? in.ConsumeIntegralInRange<int32_t>(-3, 0)
                                                                 : in.ConsumeIntegralInRange<int32_t>(1, kMaxEnvs);
        o.threads = in.ConsumeIntegralInRange<int32_t>(-2, 3);
        o.undo_depth = in.ConsumeIntegralInRange<int32_t>(-2, 6);
        o.auto_reset = in.ConsumeIntegralInRange<int32_t>(-1, 3);
        o.max_episode_steps = in.ConsumeIntegralInRange<int32_t>(-1, 5);
        o.again_mode = in.ConsumeIntegralInRange<int32_t>(-1, 2);
        o.device = in.ConsumeIntegral<int8_t>();
        psc_batch* b = reinterpret_cast<psc_batch*>(0x1);  // must be overwritten
        const bool nullOut = in.ConsumeIntegralInRange<int>(0, 31) == 0;
        const int status = p().batchCreate(in.ConsumeIntegralInRange<int>(0, 31) == 0 ? nullptr : &o, nullOut ? nullptr : &b);
        expectStatus(status, "psc_batch_create");
        if (status == PSC_OK) {
            if (!b || b == reinterpret_cast<psc_batch*>(0x1)) die("psc_batch_create returned PSC_OK without a batch");
            batches[s] = b;
            envs[s] = o.num_envs;
            int32_t n = -1;
            expectStatus(game.extra.batchSize(b, &n), "psc_batch_size");
            if (n != o.num_envs) die("psc_batch_size disagrees with num_envs");
        } else if (!nullOut && b != nullptr && b != reinterpret_cast<psc_batch*>(0x1)) {
            die("psc_batch_create failed but returned a batch");
        }
    }

    void destroy(size_t s) {
        for (size_t i = allocations.size(); i-- > 0;) {
            if (allocations[i].batch != batches[s]) continue;
            expectStatus(p().deviceFree(batches[s], allocations[i].pointer), "psc_device_free");
            allocations.erase(allocations.begin() + static_cast<std::ptrdiff_t>(i));
        }
        p().batchDestroy(batches[s]);
        batches[s] = nullptr;
        envs[s] = 0;
    }

    void reset() {
        psc_batch* b = anyBatch();
        const int32_t n = envCount(b);
        const bool allEnvs = in.ConsumeBool();
        const int32_t count = allEnvs ? (in.ConsumeIntegralInRange<int>(0, 7) ? n : index(n + 2))
                                      : in.ConsumeIntegralInRange<int32_t>(0, kMaxEnvs);
        const size_t length = static_cast<size_t>(std::max(0, std::min(count, kMaxEnvs + 2)));
        GuardedBuffer ids(length * sizeof(int32_t)), levels(length * sizeof(int32_t)), seeds(length * sizeof(uint64_t));
        const int32_t levelCount = p().info().level_count;
        for (size_t i = 0; i < length; ++i) {
            const int32_t id = index(n), level = index(levelCount);
            const uint64_t seed = in.ConsumeIntegral<uint64_t>();
            std::memcpy(ids.data() + i * 4, &id, 4);
            std::memcpy(levels.data() + i * 4, &level, 4);
            std::memcpy(seeds.data() + i * 8, &seed, 8);
        }
        if (static_cast<size_t>(count) > length) return;  // the call would read past the arrays: a caller's fault
        const bool nullLevels = in.ConsumeIntegralInRange<int>(0, 15) == 0;
        const int status = p().reset(b, allEnvs ? nullptr : reinterpret_cast<int32_t*>(ids.data()), count,
                                     nullLevels ? nullptr : reinterpret_cast<int32_t*>(levels.data()),
                                     reinterpret_cast<uint64_t*>(seeds.data()));
        expectStatus(status, "psc_reset");
    }

    void resetEntry() {
        psc_batch* b = anyBatch();
        const int32_t env = index(envCount(b));
        const int32_t entry = index(p().info().entry_count);
        const std::string seed = in.ConsumeRandomLengthString(48);
        GuardedBuffer text(seed.size() + 1);
        std::memcpy(text.data(), seed.c_str(), seed.size() + 1);
        const bool nullSeed = in.ConsumeIntegralInRange<int>(0, 15) == 0;
        expectStatus(p().resetEntry(b, env, entry, nullSeed ? nullptr : text.data()), "psc_reset_entry");
    }

    // Actions mostly valid; `n` of them.
    void fillActions(char* out, size_t n) {
        for (size_t i = 0; i < n; ++i) {
            const int32_t a = in.ConsumeIntegralInRange<int>(0, 15) == 0 ? in.ConsumeIntegral<int32_t>()
                                                                          : in.ConsumeIntegralInRange<int32_t>(0, 7);
            std::memcpy(out + i * 4, &a, 4);
        }
    }

    void step() {
        psc_batch* b = anyBatch();
        const size_t n = static_cast<size_t>(envCount(b));
        GuardedBuffer actions(n * sizeof(int32_t)), results(n * sizeof(psc_step_result));
        fillActions(actions.data(), n);
        const bool withResults = in.ConsumeBool();
        const bool nullActions = in.ConsumeIntegralInRange<int>(0, 15) == 0;
        const int status = p().step(b, nullActions ? nullptr : reinterpret_cast<int32_t*>(actions.data()),
                                    withResults ? reinterpret_cast<psc_step_result*>(results.data()) : nullptr);
        expectStatus(status, "psc_step");
    }

    void stepMany() {
        psc_batch* b = anyBatch();
        const size_t n = static_cast<size_t>(envCount(b));
        const int32_t steps = in.ConsumeIntegralInRange<int>(0, 15) == 0 ? in.ConsumeIntegralInRange<int32_t>(-5, -1)
                                                                          : in.ConsumeIntegralInRange<int32_t>(0, kMaxSteps);
        const size_t cells = n * static_cast<size_t>(std::max(steps, 0));
        GuardedBuffer actions(cells * 4), rewards(cells * 4), terminated(cells), truncated(cells), won(cells);
        fillActions(actions.data(), cells);
        auto maybe = [&](GuardedBuffer& g) { return in.ConsumeBool() ? g.data() : nullptr; };
        const int status = game.extra.stepMany(b, steps, reinterpret_cast<int32_t*>(actions.data()),
                                               reinterpret_cast<float*>(maybe(rewards)), reinterpret_cast<uint8_t*>(maybe(terminated)),
                                               reinterpret_cast<uint8_t*>(maybe(truncated)), reinterpret_cast<uint8_t*>(maybe(won)));
        expectStatus(status, "psc_step_many");
    }

    void observe() {
        psc_batch* b = anyBatch();
        const psc_game_info& info = p().info();
        const size_t needed = static_cast<size_t>(envCount(b)) * info.object_count * info.max_height * info.max_width;
        GuardedBuffer obs(bufferSize(needed));
        const bool nullBuffer = in.ConsumeIntegralInRange<int>(0, 15) == 0;
        const int status = p().observe(b, nullBuffer ? nullptr : reinterpret_cast<uint8_t*>(obs.data()), obs.size());
        expectStatus(status, "psc_observe");
        if (status == PSC_OK && obs.size() < needed) die("psc_observe accepted a buffer that is too small");
    }

    void buffers() {
        psc_batch* b = anyBatch();
        psc_buffers bufs{};
        const bool nullOut = in.ConsumeIntegralInRange<int>(0, 15) == 0;
        const int status = p().getBuffers(b, nullOut ? nullptr : &bufs);
        expectStatus(status, "psc_get_buffers");
        if (status != PSC_OK) return;
        if (bufs.num_envs != envCount(b) || bufs.device != -1 || !bufs.actions) die("psc_get_buffers: wrong buffers");
        for (int32_t i = 0; i < bufs.num_envs; ++i) {
            int32_t a;
            fillActions(reinterpret_cast<char*>(&a), 1);
            bufs.actions[i] = a;
        }
        expectStatus(p().stepBuffers(b), "psc_step_buffers");
    }

    void rollout() {
        psc_batch* b = anyBatch();
        const int32_t steps = in.ConsumeIntegralInRange<int32_t>(-2, kMaxSteps);
        psc_rollout_stats stats{};
        expectStatus(p().rollout(b, steps, in.ConsumeIntegral<uint64_t>(), in.ConsumeBool() ? &stats : nullptr),
                     "psc_rollout");
    }

    void saveState() {
        psc_batch* b = anyBatch();
        const int32_t env = index(envCount(b));
        const size_t needed = p().stateSize(b);
        if (!b && needed != 0) die("psc_state_size(NULL) is not 0");
        GuardedBuffer buffer(bufferSize(needed));
        const bool nullBuffer = in.ConsumeIntegralInRange<int>(0, 15) == 0;
        const int status = p().saveState(b, env, nullBuffer ? nullptr : buffer.data(), buffer.size());
        expectStatus(status, "psc_save_state");
        if (status == PSC_OK) saved.assign(buffer.data(), buffer.data() + needed);
    }

    // Loads the last saved state, or bytes of the input, with a few bytes of
    // the state header changed.  (The body after the header is the
    // environment's raw memory, which the plugin takes as it is: see
    // docs/robustness.md.)
    void loadState() {
        psc_batch* b = anyBatch();
        const int32_t env = index(envCount(b));
        const size_t needed = p().stateSize(b);
        std::vector<char> bytes = saved;
        if (bytes.empty() || in.ConsumeIntegralInRange<int>(0, 7) == 0) {
            const std::string raw = in.ConsumeBytesAsString(in.ConsumeIntegralInRange<size_t>(0, 256));
            bytes.assign(raw.begin(), raw.end());
        }
        bytes.resize(bufferSize(needed), '\0');
        constexpr size_t kHeaderBytes = 56;  // magic, sha1, undo capacity and count
        const int flips = in.ConsumeIntegralInRange<int>(0, 3);
        for (int k = 0; k < flips && !bytes.empty(); ++k) {
            const size_t at = in.ConsumeIntegralInRange<size_t>(0, std::min(bytes.size(), kHeaderBytes) - 1);
            bytes[at] = static_cast<char>(in.ConsumeIntegral<uint8_t>());
        }
        GuardedBuffer buffer(bytes.data(), bytes.size());
        const bool nullBuffer = in.ConsumeIntegralInRange<int>(0, 15) == 0;
        expectStatus(p().loadState(b, env, nullBuffer ? nullptr : buffer.data(), buffer.size()), "psc_load_state");
    }

    void dump() {
        psc_batch* b = anyBatch();
        const int32_t env = index(envCount(b));
        size_t needed = 0;
        const int first = p().dumpState(b, env, nullptr, 0, &needed);
        expectStatus(first, "psc_dump_state");
        GuardedBuffer buffer(bufferSize(needed));
        const bool nullNeeded = in.ConsumeBool();
        size_t needed2 = 0;
        const int status = p().dumpState(b, env, buffer.data(), buffer.size(), nullNeeded ? nullptr : &needed2);
        expectStatus(status, "psc_dump_state");
        if (status == PSC_OK && std::strlen(buffer.data()) + 1 != needed) die("psc_dump_state: the dump's length is not *needed");
    }

    void streams() {
        psc_batch* b = anyBatch();
        expectStatus(p().setStream(b, in.ConsumeBool() ? nullptr : reinterpret_cast<void*>(0x10)), "psc_set_stream");
        expectStatus(p().synchronize(b), "psc_synchronize");
        int32_t n = 0;
        expectStatus(game.extra.batchSize(b, in.ConsumeBool() ? &n : nullptr), "psc_batch_size");
    }

    // ---- search: state keys and batched expansion -------------------------

    size_t keyWords() const { return p().info().state_key_bytes / sizeof(uint64_t); }

    void startFlags() {
        psc_batch* b = anyBatch();
        const int32_t env = index(envCount(b));
        uint8_t flag = 0;
        const bool nullOut = in.ConsumeIntegralInRange<int>(0, 15) == 0;
        expectStatus(p().startWon(b, env, nullOut ? nullptr : &flag), "psc_start_won");
        expectStatus(p().startCutOff(b, env, nullOut ? nullptr : &flag), "psc_start_cut_off");
    }

    // Encodes some environments' keys; every key must decode back to itself.
    void encode() {
        psc_batch* b = anyBatch();
        const int32_t n = envCount(b);
        const int32_t count = in.ConsumeIntegralInRange<int>(0, 7) == 0 ? in.ConsumeIntegralInRange<int32_t>(-2, 0)
                                                                         : in.ConsumeIntegralInRange<int32_t>(0, kMaxEnvs);
        const size_t length = static_cast<size_t>(std::max(count, 0));
        GuardedBuffer ids(length * sizeof(int32_t)), out(length * keyWords() * sizeof(uint64_t)),
            hashes(length * sizeof(uint64_t));
        for (size_t i = 0; i < length; ++i) {
            const int32_t id = index(n);
            std::memcpy(ids.data() + i * 4, &id, 4);
        }
        const bool nullIds = in.ConsumeIntegralInRange<int>(0, 15) == 0;
        const bool withHashes = in.ConsumeBool();
        const int status = p().encodeStates(b, nullIds ? nullptr : reinterpret_cast<int32_t*>(ids.data()), count,
                                            out.data(), withHashes ? reinterpret_cast<uint64_t*>(hashes.data()) : nullptr);
        expectStatus(status, "psc_encode_states");
        if (status != PSC_OK || length == 0) return;
        keys.assign(reinterpret_cast<uint64_t*>(out.data()), reinterpret_cast<uint64_t*>(out.data()) + length * keyWords());
        std::vector<uint64_t> again(keyWords());
        for (size_t i = 0; i < length; ++i) {
            int32_t env = 0;
            std::memcpy(&env, ids.data() + i * 4, 4);
            const uint64_t* key = keys.data() + i * keyWords();
            expectStatus(p().decodeState(b, env, key), "psc_decode_state");
            expectStatus(p().encodeStates(b, &env, 1, again.data(), nullptr), "psc_encode_states");
            if (!std::equal(again.begin(), again.end(), key)) die("an encoded key does not decode back to itself");
        }
    }

    // `count` keys: the last ones, or bytes of the input, with words and bits changed.
    std::vector<uint64_t> someKeys(size_t count) {
        const size_t words = keyWords();
        std::vector<uint64_t> k(count * words, 0);
        for (size_t i = 0; i < k.size(); ++i) k[i] = keys.empty() ? 0 : keys[i % keys.size()];
        const int changes = in.ConsumeIntegralInRange<int>(0, 4);
        for (int c = 0; c < changes && !k.empty(); ++c) {
            const size_t at = in.ConsumeIntegralInRange<size_t>(0, k.size() - 1);
            switch (in.ConsumeIntegralInRange<int>(0, 3)) {
                case 0: k[at] ^= 1ull << in.ConsumeIntegralInRange<int>(0, 63); break;
                case 1: k[at] = ~0ull; break;
                case 2: k[at] = 0; break;
                default: k[at] = in.ConsumeIntegral<uint64_t>(); break;
            }
        }
        return k;
    }

    // Decodes a changed key into an environment (which later operations step).
    void decode() {
        psc_batch* b = anyBatch();
        const int32_t env = index(envCount(b));
        const std::vector<uint64_t> k = someKeys(1);
        GuardedBuffer key(k.data(), k.size() * sizeof(uint64_t));
        const bool nullKey = in.ConsumeIntegralInRange<int>(0, 15) == 0;
        expectStatus(p().decodeState(b, env, nullKey ? nullptr : key.data()), "psc_decode_state");
    }

    // Puts keys in search's form, twice: the second time must change nothing.
    void canonical() {
        psc_batch* b = anyBatch();
        const size_t count = in.ConsumeIntegralInRange<size_t>(0, 3);
        const std::vector<uint64_t> k = someKeys(count);
        GuardedBuffer buffer(k.data(), k.size() * sizeof(uint64_t)), hashes(count * sizeof(uint64_t));
        const bool withHashes = in.ConsumeBool();
        auto* h = withHashes ? reinterpret_cast<uint64_t*>(hashes.data()) : nullptr;
        const int status = p().canonicalKeys(b, buffer.data(), static_cast<int32_t>(count), h);
        expectStatus(status, "psc_canonical_keys");
        if (status != PSC_OK || count == 0) return;
        std::vector<uint64_t> once(k.size()), onceHashes(count);
        std::memcpy(once.data(), buffer.data(), buffer.size());
        if (withHashes) std::memcpy(onceHashes.data(), hashes.data(), hashes.size());
        expectStatus(p().canonicalKeys(b, buffer.data(), static_cast<int32_t>(count), h), "psc_canonical_keys");
        if (std::memcmp(once.data(), buffer.data(), buffer.size()) != 0) die("psc_canonical_keys changed a key in search's form");
        if (withHashes && std::memcmp(onceHashes.data(), hashes.data(), hashes.size()) != 0) {
            die("psc_canonical_keys hashed one key two ways");
        }
    }

    void deadline() {
        static constexpr double kSeconds[] = {0.0, 1e-9, 1e-3, 60.0, -1.0, 1e10, std::numeric_limits<double>::quiet_NaN(),
                                              std::numeric_limits<double>::infinity()};
        psc_batch* b = anyBatch();
        const size_t pick = in.ConsumeIntegralInRange<size_t>(0, std::size(kSeconds));
        const double seconds = pick < std::size(kSeconds) ? kSeconds[pick] : in.ConsumeFloatingPoint<double>();
        expectStatus(p().setDeadline(b, seconds), "psc_set_deadline");
    }

    // Expands changed keys under any actions, over any template environment.
    void expand() {
        psc_batch* b = anyBatch();
        const int32_t templateEnv = index(envCount(b));
        const int32_t count = in.ConsumeIntegralInRange<int>(0, 15) == 0 ? -1 : in.ConsumeIntegralInRange<int32_t>(0, 3);
        const int32_t actionCount = in.ConsumeIntegralInRange<int>(0, 15) == 0 ? in.ConsumeIntegralInRange<int32_t>(-1, 0)
                                                                               : in.ConsumeIntegralInRange<int32_t>(1, 6);
        const size_t parents = static_cast<size_t>(std::max(count, 0));
        const size_t children = parents * static_cast<size_t>(std::max(actionCount, 0));
        const size_t words = keyWords();
        const std::vector<uint64_t> k = someKeys(parents);
        GuardedBuffer keyBuffer(k.data(), k.size() * sizeof(uint64_t)), actions(static_cast<size_t>(std::max(actionCount, 0)) * 4),
            out(children * words * sizeof(uint64_t)), flags(children), hashes(children * sizeof(uint64_t)),
            estimates(children * sizeof(int32_t));
        fillActions(actions.data(), static_cast<size_t>(std::max(actionCount, 0)));
        const bool nullKeys = in.ConsumeIntegralInRange<int>(0, 15) == 0;
        const bool withHashes = in.ConsumeBool(), withEstimates = in.ConsumeBool();
        const int status = p().expand(b, templateEnv, nullKeys ? nullptr : keyBuffer.data(), count,
                                      reinterpret_cast<int32_t*>(actions.data()), actionCount, out.data(),
                                      reinterpret_cast<uint8_t*>(flags.data()),
                                      withHashes ? reinterpret_cast<uint64_t*>(hashes.data()) : nullptr,
                                      withEstimates ? reinterpret_cast<int32_t*>(estimates.data()) : nullptr);
        expectStatus(status, "psc_expand");
        if (status != PSC_OK) return;
        const auto* child = reinterpret_cast<const uint64_t*>(out.data());
        for (size_t c = 0; c < children; ++c) {
            const uint8_t f = static_cast<uint8_t>(flags.data()[c]);
            if (f & ~0x1Fu) die("psc_expand set an unknown flag");
            if (f & (PSC_EXPAND_INVALID | PSC_EXPAND_TIMED_OUT)) continue;
            const uint64_t* parent = k.data() + (c / static_cast<size_t>(actionCount)) * words;
            if ((f & PSC_EXPAND_UNCHANGED) && !std::equal(parent, parent + words, child + c * words)) {
                die("psc_expand flagged a child unchanged that differs from its parent");
            }
            if (withHashes) {
                std::vector<uint64_t> copy(child + c * words, child + (c + 1) * words);
                uint64_t hash = 0;
                expectStatus(p().canonicalKeys(b, copy.data(), 1, &hash), "psc_canonical_keys");
                uint64_t expanded = 0;
                std::memcpy(&expanded, hashes.data() + c * sizeof(uint64_t), sizeof expanded);
                if (hash != expanded) die("psc_expand's hash of a child is not its key's");
            }
        }
        if (children > 0) keys.assign(child, child + children * words);
    }

    void estimate() {
        psc_batch* b = anyBatch();
        const int32_t templateEnv = index(envCount(b));
        const int32_t count = in.ConsumeIntegralInRange<int>(0, 15) == 0 ? -1 : in.ConsumeIntegralInRange<int32_t>(0, 3);
        const std::vector<uint64_t> k = someKeys(static_cast<size_t>(std::max(count, 0)));
        GuardedBuffer keyBuffer(k.data(), k.size() * sizeof(uint64_t)), estimates(static_cast<size_t>(std::max(count, 0)) * 4);
        const bool nullOut = in.ConsumeIntegralInRange<int>(0, 15) == 0;
        expectStatus(p().estimateDistance(b, templateEnv, keyBuffer.data(), count,
                                          nullOut ? nullptr : reinterpret_cast<int32_t*>(estimates.data())),
                     "psc_estimate_distance");
    }

    // psc_expand's memory: allocations, copies through them, frees.
    void memory() {
        psc_batch* b = anyBatch();
        switch (in.ConsumeIntegralInRange<int>(0, 2)) {
            case 0: {
                if (allocations.size() >= 8) return;
                const size_t bytes = in.ConsumeIntegralInRange<size_t>(0, 256);
                void* pointer = reinterpret_cast<void*>(0x1);
                const bool nullOut = in.ConsumeIntegralInRange<int>(0, 15) == 0;
                const int status = p().deviceAlloc(b, bytes, nullOut ? nullptr : &pointer);
                expectStatus(status, "psc_device_alloc");
                if (status == PSC_OK) {
                    if (!pointer) die("psc_device_alloc returned PSC_OK without memory");
                    allocations.push_back({b, pointer, bytes});
                }
                break;
            }
            case 1: {
                if (allocations.empty()) return;
                const Allocation a = allocations[in.ConsumeIntegralInRange<size_t>(0, allocations.size() - 1)];
                const size_t bytes = in.ConsumeIntegralInRange<size_t>(0, a.bytes);
                GuardedBuffer host(bytes);
                const bool toDevice = in.ConsumeBool();
                const int status = p().copy(a.batch, toDevice ? a.pointer : host.data(), toDevice ? host.data() : a.pointer, bytes);
                expectStatus(status, "psc_copy");
                break;
            }
            default: {
                if (allocations.empty()) {
                    expectStatus(p().deviceFree(b, nullptr), "psc_device_free");
                    return;
                }
                const size_t i = in.ConsumeIntegralInRange<size_t>(0, allocations.size() - 1);
                expectStatus(p().deviceFree(allocations[i].batch, allocations[i].pointer), "psc_device_free");
                allocations.erase(allocations.begin() + static_cast<std::ptrdiff_t>(i));
                break;
            }
        }
    }

    void run() {
        using Operation = void (Session::*)();
        static constexpr Operation kOperations[] = {
            &Session::create,    &Session::reset,     &Session::resetEntry, &Session::step,
            &Session::stepMany,  &Session::observe,   &Session::buffers,    &Session::rollout,
            &Session::saveState, &Session::loadState, &Session::dump,       &Session::streams,
            &Session::startFlags, &Session::encode,   &Session::decode,     &Session::canonical,
            &Session::deadline,  &Session::expand,    &Session::estimate,   &Session::memory,
        };
        constexpr size_t kCount = std::size(kOperations);
        for (int ops = 0; ops < 64 && in.remaining_bytes() > 0; ++ops) {
            const size_t op = in.ConsumeIntegralInRange<size_t>(0, kCount);  // kCount: destroy
            if (op == kCount) {
                const size_t s = slot();
                if (batches[s] || in.ConsumeBool()) destroy(s);  // destroying NULL is allowed
            } else {
                (this->*kOperations[op])();
            }
        }
        for (size_t s = 0; s < batches.size(); ++s) destroy(s);
    }
};

std::vector<std::string> pathList(const char* variable, const std::string& fallback) {
    std::vector<std::string> paths;
    const char* list = std::getenv(variable);
    std::stringstream ss(list && *list ? std::string(list) : fallback);
    for (std::string p; std::getline(ss, p, ':');) {
        if (!p.empty()) paths.push_back(p);
    }
    return paths;
}

}  // namespace

// $PSC_FUZZ_PLUGINS (colon-separated plugins built elsewhere) skips the build.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
    for (const auto& plugin : pathList("PSC_FUZZ_PLUGINS", "")) games().push_back(loadPlugin(plugin, plugin));
    if (games().empty()) {
        const std::string defaults = PSC_SOURCE_DIR "/games/sokoban.txt:" PSC_SOURCE_DIR "/games/rigid.txt:" PSC_SOURCE_DIR
                                                    "/games/ice.txt";
        for (const auto& path : pathList("PSC_FUZZ_GAMES", defaults)) games().push_back(buildGame(path));
    }
    if (games().empty()) die("no games");
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    FuzzedDataProvider in(data, size);
    const LoadedGame& game = games()[in.ConsumeIntegralInRange<size_t>(0, games().size() - 1)];
    Session session{game, in};
    session.run();
    return 0;
}
