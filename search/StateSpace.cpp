#include "StateSpace.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace psc::search {

char inputLetter(int action) {
    static constexpr char kLetters[] = {'u', 'l', 'd', 'r', 'x'};
    return action >= 0 && action < 5 ? kLetters[action] : '?';
}

int actionOfLetter(char letter) {
    switch (std::tolower(static_cast<unsigned char>(letter))) {
        case 'u': return PSC_ACTION_UP;
        case 'l': return PSC_ACTION_LEFT;
        case 'd': return PSC_ACTION_DOWN;
        case 'r': return PSC_ACTION_RIGHT;
        case 'x': return PSC_ACTION_ACTION;
        default: return -1;
    }
}

namespace {

// States a call expands: enough to keep every CPU thread or the GPU busy,
// few enough that limits are checked often.
size_t defaultBatch(const SpaceOptions& o, size_t keyBytes) {
    // About 32 MB of children a call on the CPU: large keys make small batches.
    if (o.backend == Backend::Cpu) return std::clamp<size_t>((size_t{32} << 20) / (keyBytes * 5), 16, 4096);
    // About 256 MB of children on the GPU.
    const size_t byMemory = (size_t{256} << 20) / (keyBytes * 5);
    return std::max<size_t>(4096, std::min<size_t>(byMemory, size_t{1} << 20));
}

}  // namespace

StateSpace::StateSpace(const Plugin& plugin, const SpaceOptions& options, int level, std::string_view fromInputs)
    : plugin_(plugin), options_(options), level_(level) {
    const psc_game_info& info = plugin.info();
    if (level < 0 || level >= info.level_count) {
        throw std::runtime_error("level " + std::to_string(level) + " out of range [0, " + std::to_string(info.level_count) + ")");
    }
    if (!info.level_built[level]) throw std::runtime_error("level " + std::to_string(level) + " was left out of the plugin");
    for (char c : fromInputs) {
        if (actionOfLetter(c) < 0) throw std::runtime_error(std::string("not an input letter (u d l r x): '") + c + "'");
    }
    keyWords_ = info.state_key_bytes / 8;
    for (int a = 0; a < 4; ++a) inputs_.push_back(a);
    if (!(info.flags & PSC_FLAG_NOACTION)) inputs_.push_back(PSC_ACTION_ACTION);

    psc_batch_options bo = defaultBatchOptions();
    bo.backend = options.backend == Backend::Cuda ? PSC_BACKEND_CUDA : PSC_BACKEND_CPU;
    bo.threads = std::max(1, options.threads);
    bo.device = options.device;
    bo.auto_reset = PSC_AUTO_RESET_NEXT_STEP;  // a won level stays shown, as its children do
    check(plugin.batchCreate(&bo, &batch_), "creating the batch");
    const int32_t env = 0;
    check(plugin.reset(batch_, &env, 1, &level, &options.seed), "starting the level");
    uint8_t startCutOff = 0;
    check(plugin.startCutOff(batch_, env, &startCutOff), "starting the level");
    rootCutOff_ = startCutOff != 0;
    uint8_t startWon = 0;
    check(plugin.startWon(batch_, env, &startWon), "starting the level");
    startWon_ = startWon != 0;
    rootWon_ = startWon_;
    for (char c : fromInputs) {
        if (rootCutOff_ || rootWon_) break;
        const int32_t action = actionOfLetter(c);
        psc_step_result r{};
        check(plugin.step(batch_, &action, &r), "playing --from-inputs");
        rootCutOff_ = r.cut_off != 0;
        if (r.won) {
            rootWon_ = true;
            break;
        }
    }
    root_.resize(keyWords_);
    check(plugin.encodeStates(batch_, &env, 1, root_.data(), nullptr), "encoding the start");
    check(plugin.canonicalKeys(batch_, root_.data(), 1, &rootHash_), "encoding the start");
    entry_ = info.level_entries[level];

    maxBatch_ = options.maxBatch ? options.maxBatch : defaultBatch(options, info.state_key_bytes);
    if (options.backend == Backend::Cuda) {
        const size_t children = maxBatch_ * inputs_.size();
        check(plugin.deviceAlloc(batch_, maxBatch_ * keyWords_ * 8, &deviceKeys_), "allocating device memory");
        check(plugin.deviceAlloc(batch_, children * keyWords_ * 8, &deviceChildren_), "allocating device memory");
        check(plugin.deviceAlloc(batch_, children, &deviceFlags_), "allocating device memory");
        check(plugin.deviceAlloc(batch_, children * 8, &deviceHashes_), "allocating device memory");
        check(plugin.deviceAlloc(batch_, children * 4, &deviceEstimates_), "allocating device memory");
        check(plugin.deviceAlloc(batch_, inputs_.size() * 4, &deviceInputs_), "allocating device memory");
        check(plugin.copy(batch_, deviceInputs_, inputs_.data(), inputs_.size() * 4), "uploading the inputs");
    }
}

StateSpace::~StateSpace() {
    if (!batch_) return;
    for (void* p : {deviceKeys_, deviceChildren_, deviceFlags_, deviceHashes_, deviceEstimates_, deviceInputs_}) {
        if (p) plugin_.deviceFree(batch_, p);
    }
    plugin_.batchDestroy(batch_);
}

void StateSpace::check(int status, const char* what) const {
    if (status != PSC_OK) throw std::runtime_error(std::string(what) + ": " + plugin_.lastError());
}

void StateSpace::expand(const uint64_t* keys, size_t count, uint64_t* children, uint8_t* flags, uint64_t* hashes,
                        int32_t* estimates) {
    if (count > maxBatch_) throw std::logic_error("StateSpace::expand: more keys than maxBatch()");
    const int32_t n = static_cast<int32_t>(count);
    const int32_t a = static_cast<int32_t>(inputs_.size());
    if (options_.backend == Backend::Cpu) {
        check(plugin_.expand(batch_, 0, keys, n, inputs_.data(), a, children, flags, hashes, estimates), "expanding states");
        return;
    }
    const size_t out = count * inputs_.size();
    check(plugin_.copy(batch_, deviceKeys_, keys, count * keyWords_ * 8), "uploading keys");
    check(plugin_.expand(batch_, 0, deviceKeys_, n, static_cast<const int32_t*>(deviceInputs_), a, deviceChildren_,
                         static_cast<uint8_t*>(deviceFlags_), static_cast<uint64_t*>(deviceHashes_),
                         estimates ? static_cast<int32_t*>(deviceEstimates_) : nullptr),
          "expanding states");
    check(plugin_.copy(batch_, children, deviceChildren_, out * keyWords_ * 8), "reading children");
    check(plugin_.copy(batch_, flags, deviceFlags_, out), "reading children");
    check(plugin_.copy(batch_, hashes, deviceHashes_, out * 8), "reading children");
    if (estimates) check(plugin_.copy(batch_, estimates, deviceEstimates_, out * 4), "reading children");
}

void StateSpace::stage(const uint64_t* keys, size_t count) {
    if (count > maxBatch_) throw std::logic_error("StateSpace::stage: more keys than maxBatch()");
    if (options_.backend == Backend::Cuda) {
        check(plugin_.copy(batch_, deviceKeys_, keys, count * keyWords_ * 8), "uploading keys");
        return;
    }
    stagedKeys_.assign(keys, keys + count * keyWords_);
    stagedChildren_.resize(count * inputs_.size() * keyWords_);
    stagedFlags_.resize(count * inputs_.size());
    stagedHashes_.resize(count * inputs_.size());
}

void StateSpace::expandStaged(size_t count) {
    const int32_t n = static_cast<int32_t>(count);
    const int32_t a = static_cast<int32_t>(inputs_.size());
    if (options_.backend == Backend::Cuda) {
        check(plugin_.expand(batch_, 0, deviceKeys_, n, static_cast<const int32_t*>(deviceInputs_), a, deviceChildren_,
                             static_cast<uint8_t*>(deviceFlags_), static_cast<uint64_t*>(deviceHashes_), nullptr),
              "expanding states");
        return;
    }
    if (count * keyWords_ > stagedKeys_.size()) throw std::logic_error("StateSpace::expandStaged: fewer keys staged");
    check(plugin_.expand(batch_, 0, stagedKeys_.data(), n, inputs_.data(), a, stagedChildren_.data(), stagedFlags_.data(),
                         stagedHashes_.data(), nullptr),
          "expanding states");
}

void StateSpace::expandResident(const void* deviceKeys, size_t count, bool withEstimates) {
    if (options_.backend != Backend::Cuda) throw std::logic_error("StateSpace::expandResident: not a CUDA space");
    if (count > maxBatch_) throw std::logic_error("StateSpace::expandResident: more keys than maxBatch()");
    check(plugin_.expand(batch_, 0, deviceKeys, static_cast<int32_t>(count), static_cast<const int32_t*>(deviceInputs_),
                         static_cast<int32_t>(inputs_.size()), deviceChildren_, static_cast<uint8_t*>(deviceFlags_),
                         static_cast<uint64_t*>(deviceHashes_),
                         withEstimates ? static_cast<int32_t*>(deviceEstimates_) : nullptr),
          "expanding states");
}

void StateSpace::setDeadline(double seconds) {
    check(plugin_.setDeadline(batch_, std::clamp(seconds, 1e-6, 1e9)), "setting the expansion deadline");
}

void StateSpace::setStream(void* stream) { check(plugin_.setStream(batch_, stream), "setting the batch's stream"); }

void StateSpace::synchronize() { check(plugin_.synchronize(batch_), "waiting for the device"); }

void StateSpace::estimate(const uint64_t* keys, size_t count, int32_t* estimates) {
    check(plugin_.estimateDistance(batch_, 0, keys, static_cast<int32_t>(count), estimates), "estimating distances");
}

bool StateSpace::winsExactlyAtEnd(std::string_view inputs) {
    psc_batch_options bo = defaultBatchOptions();
    bo.auto_reset = PSC_AUTO_RESET_NEXT_STEP;
    Batch replay(plugin_, bo);
    const int32_t env = 0;
    replay.check(plugin_.reset(replay.get(), &env, 1, &level_, &options_.seed), "starting the level");
    for (size_t i = 0; i < inputs.size(); ++i) {
        const int32_t action = actionOfLetter(inputs[i]);
        if (action < 0) return false;
        psc_step_result r{};
        replay.check(plugin_.step(replay.get(), &action, &r), "replaying");
        if (r.won) return i + 1 == inputs.size();
    }
    return false;
}

}  // namespace psc::search
