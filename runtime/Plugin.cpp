#include "Plugin.h"

#include <dlfcn.h>

#include <stdexcept>

namespace psc {

std::unique_ptr<Plugin> Plugin::open(const std::string& path, std::string* error) {
    std::unique_ptr<Plugin> p(new Plugin);
    // dlopen searches the library path for a name without a slash; a plugin
    // path names a file, as a relative path does everywhere else.
    const std::string file = path.find('/') == std::string::npos ? "./" + path : path;
    p->handle_ = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!p->handle_) {
        *error = std::string("cannot load ") + path + ": " + dlerror();
        return nullptr;
    }
    auto sym = [&](const char* name) { return dlsym(p->handle_, name); };
    auto version = reinterpret_cast<decltype(&psc_abi_version)>(sym("psc_abi_version"));
    if (!version) {
        *error = path + " is not a psc plugin (no psc_abi_version)";
        return nullptr;
    }
    if (version() != PSC_ABI_VERSION) {
        *error = path + " implements plugin ABI version " + std::to_string(version()) + ", this loader version " +
                 std::to_string(PSC_ABI_VERSION);
        return nullptr;
    }
    auto info = reinterpret_cast<decltype(&psc_get_game_info)>(sym("psc_get_game_info"));
#define PSC_LOAD(member, name) p->member = reinterpret_cast<decltype(&name)>(sym(#name))
    PSC_LOAD(lastError, psc_last_error);
    PSC_LOAD(batchCreate, psc_batch_create);
    PSC_LOAD(batchDestroy, psc_batch_destroy);
    PSC_LOAD(reset, psc_reset);
    PSC_LOAD(resetEntry, psc_reset_entry);
    PSC_LOAD(startCutOff, psc_start_cut_off);
    PSC_LOAD(startWon, psc_start_won);
    PSC_LOAD(setDeadline, psc_set_deadline);
    PSC_LOAD(step, psc_step);
    PSC_LOAD(observe, psc_observe);
    PSC_LOAD(stateSize, psc_state_size);
    PSC_LOAD(saveState, psc_save_state);
    PSC_LOAD(loadState, psc_load_state);
    PSC_LOAD(dumpState, psc_dump_state);
    PSC_LOAD(getBuffers, psc_get_buffers);
    PSC_LOAD(stepBuffers, psc_step_buffers);
    PSC_LOAD(setStream, psc_set_stream);
    PSC_LOAD(synchronize, psc_synchronize);
    PSC_LOAD(rollout, psc_rollout);
    PSC_LOAD(encodeStates, psc_encode_states);
    PSC_LOAD(decodeState, psc_decode_state);
    PSC_LOAD(canonicalKeys, psc_canonical_keys);
    PSC_LOAD(expand, psc_expand);
    PSC_LOAD(estimateDistance, psc_estimate_distance);
    PSC_LOAD(deviceAlloc, psc_device_alloc);
    PSC_LOAD(deviceFree, psc_device_free);
    PSC_LOAD(copy, psc_copy);
#undef PSC_LOAD
    if (!info || !p->lastError || !p->batchCreate || !p->batchDestroy || !p->reset || !p->resetEntry || !p->startCutOff ||
        !p->startWon || !p->setDeadline || !p->step || !p->observe || !p->stateSize || !p->saveState || !p->loadState || !p->dumpState || !p->getBuffers ||
        !p->stepBuffers || !p->setStream || !p->synchronize || !p->rollout || !p->encodeStates || !p->decodeState || !p->canonicalKeys ||
        !p->expand || !p->estimateDistance || !p->deviceAlloc || !p->deviceFree || !p->copy) {
        *error = path + " lacks functions of the psc plugin ABI";
        return nullptr;
    }
    p->info_ = info();
    return p;
}

Plugin::~Plugin() {
    if (handle_) dlclose(handle_);
}

psc_batch_options defaultBatchOptions() {
    psc_batch_options o{};
    o.struct_size = sizeof(psc_batch_options);
    o.backend = PSC_BACKEND_CPU;
    o.num_envs = 1;
    o.threads = 1;
    o.undo_depth = 0;
    o.auto_reset = 0;
    o.max_episode_steps = 0;
    o.device = 0;
    return o;
}

Batch::Batch(const Plugin& plugin, const psc_batch_options& options) : plugin_(plugin) {
    check(plugin.batchCreate(&options, &batch_), "creating the batch");
}

Batch::~Batch() {
    if (batch_) plugin_.batchDestroy(batch_);
}

void Batch::check(int status, const char* what) const {
    if (status != PSC_OK) throw std::runtime_error(std::string(what) + ": " + plugin_.lastError());
}

std::string Batch::dump(int env) const {
    size_t needed = 0;
    plugin_.dumpState(batch_, env, nullptr, 0, &needed);
    std::string out(needed, '\0');
    check(plugin_.dumpState(batch_, env, out.data(), out.size(), &needed), "dumping the state");
    out.resize(needed ? needed - 1 : 0);
    return out;
}

}  // namespace psc
