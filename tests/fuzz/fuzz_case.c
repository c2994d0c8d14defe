/* fuzz_case.c - a libFuzzer harness over the case reader and the creation of a simulation
 * (mixsph_sim_create_from_text) plus a few time steps: whatever the bytes, the library must
 * return a status (refusing bad input with a message) and never crash, overflow a buffer, hang
 * or grow without bound. Built by ./tools/do fuzz (clang, -fsanitize=fuzzer,address,undefined;
 * CMake option MIXSPH_FUZZ), seeded with the bundled cases (cases/*.json). Every input it finds
 * that crashes becomes a regression test (tests/refused_inputs.py or a unit test).
 *
 * The input is capped by the harness's own limits, lower than the defaults, so that one input
 * costs milliseconds: at most FUZZ_MAX_PARTICLES particles (a bundled case at its own dx has up
 * to ~12,000: the seeds are run at their dx), FUZZ_MAX_SITES lattice sites. They are overrides of
 * the budget's keys (numerics.max_particles, numerics.max_lattice_sites), so a case that asks for
 * more is refused by the budget, which is part of what is fuzzed. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mixsph.h"

#define FUZZ_MAX_PARTICLES 2e4
#define FUZZ_MAX_SITES 1e6
#define FUZZ_STEPS 5

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text) return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    const mixsph_override limits[] = {{"numerics.max_particles", FUZZ_MAX_PARTICLES},
                                      {"numerics.max_lattice_sites", FUZZ_MAX_SITES}};
    char err[1024];
    mixsph_sim *s = NULL;
    if (mixsph_sim_create_from_text(text, "fuzz", limits, 2, &s, err, sizeof err) == MIXSPH_OK) {
        mixsph_sim_set_threads(s, 1);
        for (int k = 0; k < FUZZ_STEPS && mixsph_sim_step(s) == MIXSPH_OK; k++) continue;
        for (size_t k = 0; k < mixsph_sim_output_count(s); k++) (void)mixsph_sim_output_value(s, k);
    }
    mixsph_sim_destroy(s);
    free(text);
    return 0;
}
