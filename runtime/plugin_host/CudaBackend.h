// The CUDA backend's host side: loads the game's kernels (the cubin for the
// device's architecture, else PTX) with the CUDA driver API, found at run
// time with dlopen so that plugins also load on machines without a GPU, and
// keeps a batch in device memory.  PluginAbi.cpp validates each call's
// arguments and hands CUDA batches here.
#pragma once

#include <string>
#include <vector>

#include "Batch.h"

namespace psc_host {

int cudaBatchCreate(const psc_batch_options* options, psc_batch** out);
void cudaBatchDestroy(psc_batch* b);
// Starts `count` environments (all of them when envIds is NULL) at LEVELS entries with level seeds.
int cudaResetEntries(psc_batch* b, const int32_t* envIds, int32_t count, const int32_t* entries,
                     const std::vector<std::u16string>& seeds);
int cudaStep(psc_batch* b, const int32_t* actions, psc_step_result* results);
int cudaStepMany(psc_batch* b, int32_t steps, const int32_t* actions, float* rewards, uint8_t* terminated,
                 uint8_t* truncated, uint8_t* won);
int cudaObserve(psc_batch* b, uint8_t* observations, size_t size);
int cudaGetBuffers(psc_batch* b, psc_buffers* buffers);
int cudaStepBuffers(psc_batch* b);
int cudaSetStream(psc_batch* b, void* stream);
int cudaSynchronize(psc_batch* b);
int cudaRollout(psc_batch* b, int32_t steps, uint64_t seed, psc_rollout_stats* stats);
// One environment copied to `out` (game().envBytes).
int cudaFetchEnv(const psc_batch* b, int env, void* out);
// An environment and its undo snapshots, oldest first (undo: undoDepth snapshots' room).
int cudaReadState(const psc_batch* b, int env, void* out, void* undo, int* undoCount);
int cudaWriteState(psc_batch* b, int env, const void* in, const void* undo, int undoCount);
int cudaExpand(psc_batch* b, int32_t templateEnv, const void* keys, int32_t count, const int32_t* actions,
               int32_t actionCount, void* children, uint8_t* flags, uint64_t* hashes, int32_t* estimates);
int cudaAlloc(psc_batch* b, size_t bytes, void** pointer);
int cudaFree(psc_batch* b, void* pointer);
int cudaCopy(psc_batch* b, void* destination, const void* source, size_t bytes);

}  // namespace psc_host
