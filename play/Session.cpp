#include "Session.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <stdexcept>

namespace psc::play {
namespace {

// Undo entries kept; the reference keeps every one.
constexpr int kUndoDepth = 10000;

char letterOf(int action) {
    static constexpr char kLetters[] = {'u', 'l', 'd', 'r', 'x'};
    return action >= 0 && action < 5 ? kLetters[action] : '?';
}

}  // namespace

Session::Session(const Plugin& plugin, uint64_t seed) : plugin_(plugin), info_(plugin.info()), seed_(seed) {
    psc_batch_options options = defaultBatchOptions();
    options.backend = PSC_BACKEND_CPU;
    options.num_envs = 1;
    options.threads = 1;
    options.undo_depth = kUndoDepth;
    options.auto_reset = PSC_AUTO_RESET_OFF;
    options.again_mode = PSC_AGAIN_ONE_TURN;
    if (plugin_.batchCreate(&options, &batch_) != PSC_OK) {
        throw std::runtime_error(std::string("cannot create the game: ") + plugin_.lastError());
    }
    observation_.assign(static_cast<size_t>(info_.object_count) * info_.max_width * info_.max_height, 0);
}

Session::~Session() { plugin_.batchDestroy(batch_); }

void Session::startEntry(int entry) {
    if (entry < 0 || entry >= info_.entry_count) throw std::out_of_range("no LEVELS entry " + std::to_string(entry));
    const std::string seed = std::to_string(seed_);
    if (plugin_.resetEntry(batch_, 0, entry, seed.c_str()) != PSC_OK) {
        throw std::runtime_error(std::string("cannot start the level: ") + plugin_.lastError());
    }
    againing_ = false;
    refresh();
    beginLevelBookkeeping();
}

void Session::beginLevelBookkeeping() {
    moves_ = 0;
    pathTo_.clear();
    if (screen_ == Screen::Level) {
        path_ = "";
        lastKey_ = key();
        pathTo_[lastKey_] = "";
    } else {
        path_.reset();
        lastKey_.clear();
    }
}

StepReport Session::step(int action) {
    const int levelBefore = level();
    const bool chainTurn = againing_ && action != PSC_ACTION_UNDO && action != PSC_ACTION_RESTART;
    const int32_t a = action;
    psc_step_result result{};
    if (plugin_.step(batch_, &a, &result) != PSC_OK) {
        throw std::runtime_error(std::string("the game failed: ") + plugin_.lastError());
    }
    refresh();
    againing_ = result.againing != 0;
    StepReport report;
    report.cutOff = result.cut_off != 0;
    report.againing = againing_;
    if (result.message >= 0 && result.message < info_.rule_message_count) report.message = info_.rule_messages[result.message];
    if (result.won) {
        report.won = true;
        report.wonLevel = levelBefore;
        report.completed = screen_ == Screen::Title;
        beginLevelBookkeeping();
        return report;
    }
    if (screen_ != Screen::Level) return report;
    // The bookkeeping counts an input with its whole chain, as search does.
    if (chainTurn) action = chainInput_;
    if (againing_) {
        chainInput_ = action;
        return report;
    }
    const std::string now = key();
    if (action <= PSC_ACTION_ACTION) {
        if (now != lastKey_) {
            ++moves_;
            if (path_) *path_ += letterOf(action);
        }
    } else {
        // Undo, restart and ticks lead to a state that inputs reached before, or to one no inputs reach.
        auto known = pathTo_.find(now);
        if (known != pathTo_.end()) path_ = known->second;
        else path_.reset();
        if (action == PSC_ACTION_UNDO && now != lastKey_) moves_ = std::max(0, moves_ - 1);
        if (action == PSC_ACTION_RESTART) moves_ = 0;
    }
    if (path_) moves_ = static_cast<int>(path_->size());
    if (path_) {
        auto [at, added] = pathTo_.emplace(now, *path_);
        if (!added && path_->size() < at->second.size()) at->second = *path_;
    }
    lastKey_ = now;
    return report;
}

int Session::level() const {
    if (screen_ != Screen::Level) return -1;
    for (int l = 0; l < info_.level_count; ++l) {
        if (info_.level_entries[l] == entry_) return l;
    }
    return -1;
}

int Session::levelAtOrAfter(int entry) const {
    for (int l = 0; l < info_.level_count; ++l) {
        if (info_.level_entries[l] >= entry) return l;
    }
    return -1;
}

void Session::refresh() {
    size_t needed = 0;
    plugin_.dumpState(batch_, 0, nullptr, 0, &needed);
    std::string dump(needed, '\0');
    if (plugin_.dumpState(batch_, 0, dump.data(), dump.size(), &needed) != PSC_OK) {
        throw std::runtime_error(std::string("cannot read the game's state: ") + plugin_.lastError());
    }
    dump.resize(needed - 1);
    const nlohmann::json state = nlohmann::json::parse(dump);
    const std::string screen = state.at("screen").get<std::string>();
    screen_ = screen == "title" ? Screen::Title : screen == "message" ? Screen::Message : Screen::Level;
    entry_ = state.at("level").get<int>();
    message_ = state.at("message").is_string() ? state.at("message").get<std::string>() : std::string();
    width_ = state.at("width").get<int>();
    height_ = state.at("height").get<int>();
    if (plugin_.observe(batch_, observation_.data(), observation_.size()) != PSC_OK) {
        throw std::runtime_error(std::string("cannot observe the game: ") + plugin_.lastError());
    }
}

std::string Session::key() const {
    std::vector<uint64_t> words((info_.state_key_bytes + 7) / 8);  // keys are 8-byte aligned
    const int32_t env = 0;
    if (plugin_.encodeStates(batch_, &env, 1, words.data(), nullptr) != PSC_OK) {
        throw std::runtime_error(std::string("cannot encode the game's state: ") + plugin_.lastError());
    }
    return std::string(reinterpret_cast<const char*>(words.data()), info_.state_key_bytes);
}

}  // namespace psc::play
