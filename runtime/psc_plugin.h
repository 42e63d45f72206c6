/* psc plugin ABI, version 6.
 *
 * Every plugin psc builds (`psc game.txt -o game.so`) exports these C
 * functions.  A plugin simulates one PuzzleScript game for a batch of
 * environments, exactly as the reference engine would, on the CPU (and on a
 * CUDA device when built with --target cuda or all).
 *
 * Conventions:
 *  - Levels are numbered from 0 over the playable levels; message entries are
 *    not counted.  Only psc_reset_entry takes an entry index of the game's
 *    LEVELS section, message entries included (as the corpus' traces do).
 *  - Actions: 0 up, 1 left, 2 down, 3 right, 4 action, 5 undo, 6 restart,
 *    7 tick (a turn with no input).  One step is one action followed by every
 *    `again` turn it triggers (unless the batch's again_mode is
 *    PSC_AGAIN_ONE_TURN, for players that draw each turn).
 *  - Every function returns PSC_OK or an error code; psc_last_error() then
 *    says what went wrong, in words.
 *  - Observations are multi-hot object planes, uint8, shape
 *    (num_envs, channels, max_height, max_width); channel c is the object
 *    game_info.object_names[c]; cells outside a smaller level are 0.
 */
#ifndef PSC_PLUGIN_H
#define PSC_PLUGIN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define PSC_ABI_VERSION 6

/* Plugins are built with hidden symbols; these are the exported ones. */
#if defined(__GNUC__)
#define PSC_API __attribute__((visibility("default")))
#else
#define PSC_API
#endif

typedef enum psc_status {
    PSC_OK = 0,
    PSC_ERROR_NULL_POINTER = 1,
    PSC_ERROR_ABI_VERSION = 2,
    PSC_ERROR_BAD_ARGUMENT = 3,
    PSC_ERROR_BAD_ENV = 4,
    PSC_ERROR_BAD_LEVEL = 5,
    PSC_ERROR_BAD_ACTION = 6,
    PSC_ERROR_BAD_STATE = 7,
    PSC_ERROR_BUFFER_TOO_SMALL = 8,
    PSC_ERROR_BACKEND_UNAVAILABLE = 9,
    PSC_ERROR_OUT_OF_MEMORY = 10,
    PSC_ERROR_DEVICE = 11
} psc_status;

typedef enum psc_backend { PSC_BACKEND_CPU = 0, PSC_BACKEND_CUDA = 1 } psc_backend;

/* What happens when an episode ends (a win, or max_episode_steps). */
typedef enum psc_auto_reset {
    PSC_AUTO_RESET_OFF = 0,       /* play on as the reference engine does: next level, messages, title */
    PSC_AUTO_RESET_SAME_STEP = 1, /* the ending step restarts the level; its observation is the new start */
    PSC_AUTO_RESET_NEXT_STEP = 2  /* the ending step shows the final state; the next step restarts the level
                                     (its action is ignored), as Gymnasium's NEXT_STEP mode */
} psc_auto_reset;

/* How a step treats the `again` turns an input sets off. */
typedef enum psc_again_mode {
    PSC_AGAIN_SETTLE = 0,   /* the step runs them all, as the reference's test harness (and search, and training) */
    PSC_AGAIN_ONE_TURN = 1  /* the step runs one turn; psc_step_result.againing says another is due, which the
                               next step runs whatever its action (but undo and restart), as the reference's
                               player runs one every again_interval seconds and drops keys meanwhile */
} psc_again_mode;

typedef enum psc_action {
    PSC_ACTION_UP = 0,
    PSC_ACTION_LEFT = 1,
    PSC_ACTION_DOWN = 2,
    PSC_ACTION_RIGHT = 3,
    PSC_ACTION_ACTION = 4,
    PSC_ACTION_UNDO = 5,
    PSC_ACTION_RESTART = 6,
    PSC_ACTION_TICK = 7,
    PSC_ACTION_COUNT = 8
} psc_action;

/* Prelude flags of the game (game_info.flags). */
enum {
    PSC_FLAG_NOACTION = 1u << 0,
    PSC_FLAG_NOUNDO = 1u << 1,
    PSC_FLAG_NORESTART = 1u << 2,
    PSC_FLAG_REQUIRE_PLAYER_MOVEMENT = 1u << 3,
    PSC_FLAG_RUN_RULES_ON_LEVEL_START = 1u << 4,
    PSC_FLAG_REALTIME = 1u << 5,
    PSC_FLAG_USES_RANDOM = 1u << 6,
    PSC_FLAG_HAS_RIGID = 1u << 7
};

typedef struct psc_game_info {
    uint32_t abi_version;
    const char* title;
    const char* author;
    const char* homepage;
    const char* source_name;   /* the file psc compiled */
    const char* source_sha1;   /* sha1 of the game text */
    const char* generator;     /* psc version and build options */
    uint32_t flags;            /* PSC_FLAG_* */
    uint32_t backends;         /* bit PSC_BACKEND_* set for each backend built in */

    int32_t object_count;              /* observation channels */
    const char* const* object_names;   /* lower case, in channel order */
    const int32_t* object_layers;      /* collision layer of each channel */
    int32_t layer_count;

    int32_t level_count;               /* playable levels */
    const int32_t* level_entries;      /* entry index of each level */
    const uint8_t* level_built;        /* 0 for levels left out of this plugin (psc --levels) */
    const int32_t* level_widths;
    const int32_t* level_heights;
    int32_t max_width;                 /* observation plane size */
    int32_t max_height;

    int32_t entry_count;               /* LEVELS entries, messages included */
    const uint8_t* entry_is_message;
    const char* const* entry_messages; /* message text, or "" for levels */

    int32_t action_count;              /* PSC_ACTION_COUNT */
    double realtime_interval;          /* seconds, 0 when none */

    /* Graphics, for rendering: channel c's sprite is 5x5 palette indices
     * object_sprites[c * 25 + row * 5 + column] (-1: transparent) into the
     * colours object_colors[c * 10 + i] (0xRRGGBB).  Cells draw their objects
     * in channel order over background_color. */
    const int8_t* object_sprites;
    const uint32_t* object_colors;
    uint32_t background_color;
    uint32_t text_color;

    uint32_t state_key_bytes;          /* size of a state key (psc_encode_states), a multiple of 8 */

    double again_interval;             /* seconds between again turns in the reference's player */
    int32_t rule_message_count;        /* distinct texts of rules' `message` commands */
    const char* const* rule_messages;  /* psc_step_result.message indexes these */
} psc_game_info;

typedef struct psc_batch psc_batch;

typedef struct psc_batch_options {
    uint32_t struct_size;      /* sizeof(psc_batch_options) */
    int32_t backend;           /* psc_backend */
    int32_t num_envs;
    int32_t threads;           /* CPU worker threads; 0 = one per core */
    int32_t undo_depth;        /* undo entries kept per environment; 0 disables undo */
    int32_t auto_reset;        /* psc_auto_reset */
    int32_t max_episode_steps; /* with auto_reset: truncate episodes after this many steps; 0 = never */
    int32_t device;            /* CUDA device ordinal */
    int32_t again_mode;        /* psc_again_mode */
} psc_batch_options;

/* Step results for one environment. */
typedef struct psc_step_result {
    float reward;         /* 1 for each level won in the step */
    uint8_t terminated;   /* auto_reset: the level was won; otherwise: the game was completed */
    uint8_t truncated;    /* auto_reset: max_episode_steps reached */
    uint8_t won;          /* a level was won in this step */
    uint8_t cut_off;      /* an endless `again` chain was cut off */
    int32_t episode_steps;
    int32_t message;      /* the rule message (game_info.rule_messages) the reference's player would have shown
                             in this step, the first if several, or -1; its test harness shows none and psc
                             follows the harness, so the level is not held on a message screen */
    uint8_t againing;     /* PSC_AGAIN_ONE_TURN: an again turn is due (the next step runs it) */
    uint8_t reserved[3];  /* zero */
} psc_step_result;

PSC_API uint32_t psc_abi_version(void);
PSC_API const psc_game_info* psc_get_game_info(void);
/* The message of the last failed call on this thread. */
PSC_API const char* psc_last_error(void);

PSC_API int psc_batch_create(const psc_batch_options* options, psc_batch** batch);
PSC_API void psc_batch_destroy(psc_batch* batch);
PSC_API int psc_batch_size(const psc_batch* batch, int32_t* num_envs);

/* Reset environments env_ids[i] to playable level levels[i] with seed
 * seeds[i] (the random stream of a level load is seeded with the seed's
 * decimal digits).  env_ids may be NULL: then count must be num_envs and
 * environment i gets levels[i] and seeds[i]. */
PSC_API int psc_reset(psc_batch* batch, const int32_t* env_ids, int32_t count, const int32_t* levels, const uint64_t* seeds);
/* Reset one environment to LEVELS entry `entry` (message entries counted),
 * seeding every level load with the string `seed` (UTF-8), as the corpus
 * harness does. */
PSC_API int psc_reset_entry(psc_batch* batch, int32_t env, int32_t entry, const char* seed);
/* Whether the last reset of environment `env` (psc_reset, psc_reset_entry or
 * an automatic reset) started a level whose start turn ran an `again` chain
 * that never settled and was cut off after 10,000 turns.  The reference
 * engine never finishes such a start, so no input can be played on it.
 * Since ABI version 4. */
PSC_API int psc_start_cut_off(const psc_batch* batch, int32_t env, uint8_t* cut_off);
/* Whether the last reset of environment `env` started a level that its start
 * won before any input: a `run_rules_on_level_start` turn queued an `again`
 * chain whose turns satisfied the win conditions (the start turn itself
 * never wins).  The reference engine then shows the next entry before the
 * first input; an environment with auto_reset shows the won level, as after
 * a winning step.  Such a level is solved by no input at all.  Since ABI
 * version 5. */
PSC_API int psc_start_won(const psc_batch* batch, int32_t env, uint8_t* won);
/* One action per environment; results may be NULL. */
PSC_API int psc_step(psc_batch* batch, const int32_t* actions, psc_step_result* results);
/* Observations of all environments: num_envs * object_count * max_height * max_width bytes. */
PSC_API int psc_observe(psc_batch* batch, uint8_t* observations, size_t size);

/* Buffers owned by the batch, for stepping without copies: host memory for
 * CPU batches, device memory for CUDA batches (device says which).  The
 * caller writes actions, calls psc_step_buffers, and reads the rest. */
typedef struct psc_buffers {
    int32_t device;          /* -1: host memory; otherwise the CUDA device ordinal */
    int32_t num_envs;
    int32_t* actions;        /* [num_envs] */
    uint8_t* observations;   /* [num_envs][object_count][max_height][max_width] */
    float* rewards;          /* [num_envs] */
    uint8_t* terminated;     /* [num_envs] */
    uint8_t* truncated;      /* [num_envs] */
    uint8_t* won;            /* [num_envs] */
    int32_t* episode_steps;  /* [num_envs] */
} psc_buffers;

PSC_API int psc_get_buffers(psc_batch* batch, psc_buffers* buffers);
/* One step of every environment with buffers.actions; fills the result
 * buffers and the observations.  CUDA batches queue it on their stream. */
PSC_API int psc_step_buffers(psc_batch* batch);
/* Runs `steps` steps: step k gives environment i the action
 * actions[k * num_envs + i] and writes its results to rewards, terminated,
 * truncated and won at the same index (any of them may be NULL); the final
 * observations go to the batch's observation buffer.  Pointers are host
 * memory for CPU batches and device memory for CUDA batches, whose work is
 * queued on the batch's stream: there, a step with an action outside [0, 8)
 * is skipped and the next psc_synchronize reports PSC_ERROR_BAD_ACTION. */
PSC_API int psc_step_many(psc_batch* batch, int32_t steps, const int32_t* actions, float* rewards, uint8_t* terminated,
                          uint8_t* truncated, uint8_t* won);
/* CUDA batches: queue work on this stream (a cudaStream_t; NULL = default). */
PSC_API int psc_set_stream(psc_batch* batch, void* stream);
/* Waits for the batch's queued work; reports invalid device actions skipped since the last call. */
PSC_API int psc_synchronize(psc_batch* batch);

/* Runs `steps` steps of every environment with uniformly random actions
 * (among the game's directions, plus action unless noaction), auto-resetting
 * finished episodes, without observations: the fast path for throughput.
 * Random actions come from a counter-based generator keyed by `seed`. */
typedef struct psc_rollout_stats {
    int64_t steps;     /* environment steps run */
    int64_t wins;      /* levels won */
    int64_t episodes;  /* episodes ended (won or truncated) */
} psc_rollout_stats;
PSC_API int psc_rollout(psc_batch* batch, int32_t steps, uint64_t seed, psc_rollout_stats* stats);

/* Saving and restoring one environment (undo history included), on either backend. */
PSC_API size_t psc_state_size(const psc_batch* batch);
PSC_API int psc_save_state(const psc_batch* batch, int32_t env, void* buffer, size_t size);
PSC_API int psc_load_state(psc_batch* batch, int32_t env, const void* buffer, size_t size);

/* The environment's state as a JSON record in the corpus' form: level,
 * screen, message, won, width, height, palette, rows.  *needed receives the
 * size (with the terminating NUL); the call fails with
 * PSC_ERROR_BUFFER_TOO_SMALL when size is smaller. */
PSC_API int psc_dump_state(const psc_batch* batch, int32_t env, char* buffer, size_t size, size_t* needed);

/* ---- State keys and batched expansion, for search ----------------------
 * A state key is game_info.state_key_bytes bytes (8-byte aligned) holding
 * everything that decides an environment's future between two inputs: two
 * environments with equal keys behave identically under every sequence of
 * inputs, their undo histories aside.  It holds the entry shown and its
 * screen flags, the level's objects, and only where the game needs them the
 * restart target (games with `checkpoint`), lingering movements (late
 * `randomdir`) and the random stream's state (games that use random).
 * The level's size, the seed and the batch's settings come from a template
 * environment, which must show the key's entry.  docs/search.md says more. */

/* Keys (and their 64-bit hashes, if hashes is not NULL) of environments
 * env_ids[0..count), in host memory on either backend. */
PSC_API int psc_encode_states(const psc_batch* batch, const int32_t* env_ids, int32_t count, void* keys,
                              uint64_t* hashes);
/* Puts environment env in the state of `key` (host memory); its undo history
 * is cleared.  The environment must show the key's entry, and the key must be
 * a state of its level: a key with an object outside the level's cells, or a
 * header bit no state sets, is refused with PSC_ERROR_BAD_STATE (as by
 * psc_estimate_distance; psc_expand flags its children PSC_EXPAND_INVALID). */
PSC_API int psc_decode_state(psc_batch* batch, int32_t env, const void* key);

/* Puts `count` keys (host memory) in search's form, the form of
 * psc_expand's children, and writes their hashes where hashes is not NULL.
 * Objects that nothing but their own creation tells apart (no rule, win
 * condition or move sound names one without the other, as a snake's body
 * segments drawn two ways) have their cells on one of them, so that states
 * differing only in which stands where have one key; such a key decodes to a
 * state that behaves as the original, drawn with that one object.  Keys of
 * games with no such objects are left as they are.  Since ABI version 6. */
PSC_API int psc_canonical_keys(const psc_batch* batch, void* keys, int32_t count, uint64_t* hashes);

/* psc_expand's per-child flags. */
enum {
    PSC_EXPAND_WON = 1u << 0,       /* the input won the level (the child stays on it) */
    PSC_EXPAND_UNCHANGED = 1u << 1, /* the child's key equals its parent's */
    PSC_EXPAND_CUT_OFF = 1u << 2,   /* an endless `again` chain was cut off */
    PSC_EXPAND_INVALID = 1u << 3,   /* not expanded: a bad action, a key of another entry than the template's, or
                                       one that is no state of its level (an object outside the level's cells) */
    PSC_EXPAND_TIMED_OUT = 1u << 4  /* not expanded: psc_set_deadline's deadline had passed (the key is not a child) */
};
/* A deadline for psc_expand, `seconds` from now (0: none): once it has
 * passed, an expansion stops within 16 `again` turns and flags every child
 * it has not finished PSC_EXPAND_TIMED_OUT, so that a search stops near its
 * time limit even where one input runs a long chain.  On a CUDA batch the
 * deadline is put on the GPU's clock at the batch's first expansion with
 * one.  Since ABI version 4 (CUDA batches since psc 0.1.0 of 2026-11-27). */
PSC_API int psc_set_deadline(psc_batch* batch, double seconds);
/* The children of `count` keys under `action_count` inputs each: child
 * i * action_count + a is key i after input actions[a] (psc_action; undo has
 * no history to go back to), decoded over environment template_env, whose
 * state is left as it was.  Writes the children's keys, in search's form
 * (psc_canonical_keys; since ABI version 6), flags (PSC_EXPAND_*)
 * and, where not NULL, their hashes and psc_estimate_distance's estimates
 * (so that best-first search needs no second pass).  Pointers are host memory for
 * CPU batches; for CUDA batches device memory (psc_device_alloc), with the
 * work queued on the batch's stream (psc_synchronize waits for it): plugins
 * built with psc --search-kernels (psc solve builds them so), others answer
 * PSC_ERROR_BACKEND_UNAVAILABLE; host memory that CUDA does not know (not
 * allocated or registered with it) is refused there with PSC_ERROR_BAD_ARGUMENT. */
PSC_API int psc_expand(psc_batch* batch, int32_t template_env, const void* keys, int32_t count, const int32_t* actions,
                       int32_t action_count, void* children, uint8_t* flags, uint64_t* hashes, int32_t* estimates);

/* An estimate of the inputs each key (host memory, on either backend) still
 * needs to win, from the game's win conditions: the cells that break a `no`
 * condition, and for `all X on Y` and `some X on Y` the Manhattan distances
 * from the X not on a Y to the nearest Y; 0 when every condition holds.  Not
 * a lower bound in general: one input may move many objects, or one far. */
PSC_API int psc_estimate_distance(const psc_batch* batch, int32_t template_env, const void* keys, int32_t count,
                                  int32_t* estimates);

/* Memory psc_expand can use on the batch's backend (device memory for CUDA
 * batches, host memory for CPU ones), and copies between any two pointers
 * (host or device; a copy waits for the batch's queued work first). */
PSC_API int psc_device_alloc(psc_batch* batch, size_t bytes, void** pointer);
PSC_API int psc_device_free(psc_batch* batch, void* pointer);
PSC_API int psc_copy(psc_batch* batch, void* destination, const void* source, size_t bytes);

#ifdef __cplusplus
}
#endif

#endif /* PSC_PLUGIN_H */
