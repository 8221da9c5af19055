/* The smallest host: compile a .psys file, run it for two seconds at 60 steps a second,
 * and print what each type draws — reading the draw columns where the system keeps them.
 *
 *   minimal FILE [BACKEND]        BACKEND: llvm (the default), interp or glsl
 */
#include <stdio.h>
#include <stdlib.h>

#include <psys/psys.h>

/* Prints an error's message (its diagnostics, for a compilation), frees it: 1 if there was one. */
static int failed(psys_error* error) {
    if (!error) return 0;
    fprintf(stderr, "%s\n", psys_error_message(error));
    psys_error_free(error);
    return 1;
}

int main(int argc, char** argv) {
    psys_options options;
    psys_system* sys = NULL;
    size_t type;
    int frame;
    if (argc < 2) {
        fprintf(stderr, "usage: minimal FILE [BACKEND]\n");
        return 2;
    }
    psys_options_init(&options);
    if (argc > 2) options.backend = argv[2];
    if (failed(psys_compile_file(argv[1], &options, &sys))) return 1;
    printf("psys %s, %s on %s\n", psys_version(), argv[1], options.backend);

    for (frame = 0; frame < 120; ++frame)
        if (failed(psys_step(sys, 1.0 / 60))) break;

    for (type = 0; type < psys_type_count(sys); ++type) {
        psys_draw draw;
        psys_type_stats stats;
        size_t row, drawn = 0;
        float highest = -1e30f;
        if (failed(psys_get_draw(sys, type, &draw)) || failed(psys_get_type_stats(sys, type, &stats))) break;
        /* On the CPU backends the columns are the system's own arrays (on the GPU's, GL
         * buffers: draw.visible.gl_buffer). */
        if (draw.visible.data && draw.position[1].data) {
            const float* visible = (const float*)draw.visible.data;
            const float* y = (const float*)draw.position[1].data;
            for (row = 0; row < draw.rows; ++row)
                if (visible[row] == 1.0f) {
                    ++drawn;
                    if (y[row] > highest) highest = y[row];
                }
            printf("%ss drawn: %zu (highest at y = %.2f), created %llu, killed %llu\n", psys_type_name(sys, type),
                   drawn, drawn ? highest : 0.0f, (unsigned long long)stats.created,
                   (unsigned long long)stats.killed);
        } else {
            printf("%ss: %zu alive (%s), created %llu, killed %llu\n", psys_type_name(sys, type), stats.live,
                   draw.visible.gl_buffer ? "drawn from GL buffers" : "drawing nothing",
                   (unsigned long long)stats.created, (unsigned long long)stats.killed);
        }
    }
    psys_system_free(sys);
    return 0;
}
