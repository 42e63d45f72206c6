// ---- psc template: no CUDA backend ---------------------------------------
// This plugin was built for the CPU only; CUDA batches are refused.

struct psc_batch;

static int psc_cuda_batch_create(const psc_batch_options*, psc_batch**) {
    return psc_game::fail(PSC_ERROR_BACKEND_UNAVAILABLE, "this plugin was built without the CUDA backend (psc --target cuda)");
}
static bool psc_cuda_batch_destroy(psc_batch*) { return false; }
static bool psc_cuda_owns(const psc_batch*) { return false; }
static int psc_cuda_reset(psc_batch*, const int32_t*, int32_t, const int32_t*, const uint64_t*) { return PSC_ERROR_BACKEND_UNAVAILABLE; }
static int psc_cuda_step(psc_batch*, const int32_t*, psc_step_result*) { return PSC_ERROR_BACKEND_UNAVAILABLE; }
static int psc_cuda_step_many(psc_batch*, int32_t, const int32_t*, float*, uint8_t*, uint8_t*, uint8_t*) {
    return PSC_ERROR_BACKEND_UNAVAILABLE;
}
static int psc_cuda_observe(psc_batch*, uint8_t*, size_t) { return PSC_ERROR_BACKEND_UNAVAILABLE; }
static int psc_cuda_get_buffers(psc_batch*, psc_buffers*) { return PSC_ERROR_BACKEND_UNAVAILABLE; }
static int psc_cuda_step_buffers(psc_batch*) { return PSC_ERROR_BACKEND_UNAVAILABLE; }
static int psc_cuda_set_stream(psc_batch*, void*) { return PSC_ERROR_BACKEND_UNAVAILABLE; }
static int psc_cuda_synchronize(psc_batch*) { return PSC_ERROR_BACKEND_UNAVAILABLE; }
static int psc_cuda_rollout(psc_batch*, int32_t, uint64_t, psc_rollout_stats*) { return PSC_ERROR_BACKEND_UNAVAILABLE; }
static int psc_cuda_reset_entries(psc_batch*, const int32_t*, int32_t, const int32_t*, const std::vector<std::u16string>&) {
    return PSC_ERROR_BACKEND_UNAVAILABLE;
}
static int psc_cuda_fetch_env(const psc_batch*, int, psc_game::Env*) { return PSC_ERROR_BACKEND_UNAVAILABLE; }
static int psc_cuda_read_state(const psc_batch*, int, psc_game::Env*, std::vector<psc_game::Snapshot>&) {
    return PSC_ERROR_BACKEND_UNAVAILABLE;
}
static int psc_cuda_write_state(psc_batch*, int, const psc_game::Env&, const std::vector<psc_game::Snapshot>&) {
    return PSC_ERROR_BACKEND_UNAVAILABLE;
}
static int psc_cuda_expand(psc_batch*, int32_t, const void*, int32_t, const int32_t*, int32_t, void*, uint8_t*, uint64_t*,
                           int32_t*) {
    return PSC_ERROR_BACKEND_UNAVAILABLE;
}
static int psc_cuda_alloc(psc_batch*, size_t, void**) { return PSC_ERROR_BACKEND_UNAVAILABLE; }
static int psc_cuda_free(psc_batch*, void*) { return PSC_ERROR_BACKEND_UNAVAILABLE; }
static int psc_cuda_copy(psc_batch*, void*, const void*, size_t) { return PSC_ERROR_BACKEND_UNAVAILABLE; }
