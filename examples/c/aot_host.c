/* A host of an ahead-of-time build: the fountain sample compiled by `psysc build` into
 * fountain.a and fountain.h (examples/CMakeLists.txt does it), linked with libpsys_runtime —
 * no compiler, no LLVM in the process. Its extern is set through the header's typed setter:
 * a misspelt name is an error of this file's compilation, not of a run.
 *
 *   aot_host [POPULATION]
 */
#include <stdio.h>
#include <stdlib.h>

#include "fountain.h"

static int failed(psys_error* error) {
    if (!error) return 0;
    fprintf(stderr, "%s\n", psys_error_message(error));
    psys_error_free(error);
    return 1;
}

int main(int argc, char** argv) {
    psys_system* sys = NULL;
    psys_type_stats drops;
    int frame;
    if (failed(fountain_open(NULL, &sys))) return 1;
    if (argc > 1 && failed(fountain_set_population(sys, (float)atof(argv[1])))) return 1;
    for (frame = 0; frame < 240; ++frame)
        if (failed(psys_step(sys, 1.0 / 60))) return 1;
    if (failed(psys_get_type_stats(sys, fountain_type_drop, &drops))) return 1;
    printf("fountain (ahead of time, %s's kernels): %zu drops alive after 4 s, %llu created\n",
           psys_aot_choose_cpu(&fountain_aot)->name, drops.live, (unsigned long long)drops.created);
    psys_system_free(sys);
    return 0;
}
