// Loading a psc plugin: dlopen, symbol lookup and the ABI version check.
// Training code can use this class, or call the C functions directly.
#pragma once

#include <memory>
#include <string>

#include "psc_plugin.h"

namespace psc {

class Plugin {
public:
    // Opens the plugin at `path`; returns null and sets *error on failure.
    static std::unique_ptr<Plugin> open(const std::string& path, std::string* error);
    ~Plugin();
    Plugin(const Plugin&) = delete;
    Plugin& operator=(const Plugin&) = delete;

    const psc_game_info& info() const { return *info_; }

    decltype(&psc_last_error) lastError = nullptr;
    decltype(&psc_batch_create) batchCreate = nullptr;
    decltype(&psc_batch_destroy) batchDestroy = nullptr;
    decltype(&psc_reset) reset = nullptr;
    decltype(&psc_reset_entry) resetEntry = nullptr;
    decltype(&psc_start_cut_off) startCutOff = nullptr;
    decltype(&psc_start_won) startWon = nullptr;
    decltype(&psc_set_deadline) setDeadline = nullptr;
    decltype(&psc_step) step = nullptr;
    decltype(&psc_observe) observe = nullptr;
    decltype(&psc_state_size) stateSize = nullptr;
    decltype(&psc_save_state) saveState = nullptr;
    decltype(&psc_load_state) loadState = nullptr;
    decltype(&psc_dump_state) dumpState = nullptr;
    decltype(&psc_get_buffers) getBuffers = nullptr;
    decltype(&psc_step_buffers) stepBuffers = nullptr;
    decltype(&psc_set_stream) setStream = nullptr;
    decltype(&psc_synchronize) synchronize = nullptr;
    decltype(&psc_rollout) rollout = nullptr;
    decltype(&psc_encode_states) encodeStates = nullptr;
    decltype(&psc_decode_state) decodeState = nullptr;
    decltype(&psc_canonical_keys) canonicalKeys = nullptr;
    decltype(&psc_expand) expand = nullptr;
    decltype(&psc_estimate_distance) estimateDistance = nullptr;
    decltype(&psc_device_alloc) deviceAlloc = nullptr;
    decltype(&psc_device_free) deviceFree = nullptr;
    decltype(&psc_copy) copy = nullptr;

private:
    Plugin() = default;
    void* handle_ = nullptr;
    const psc_game_info* info_ = nullptr;
};

// A batch that frees itself; throws std::runtime_error with the plugin's message on errors.
class Batch {
public:
    Batch(const Plugin& plugin, const psc_batch_options& options);
    ~Batch();
    Batch(const Batch&) = delete;
    Batch& operator=(const Batch&) = delete;

    psc_batch* get() const { return batch_; }
    // Throws unless status is PSC_OK.
    void check(int status, const char* what) const;
    std::string dump(int env) const;

private:
    const Plugin& plugin_;
    psc_batch* batch_ = nullptr;
};

psc_batch_options defaultBatchOptions();

}  // namespace psc
