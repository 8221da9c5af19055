/* Runs an ahead-of-time build (linked in: AOT_SYMBOL names its psys_aot), drawing every
 * frame as `psysc run` does, and prints what it draws every few frames as `psysc run --dump`
 * does (frame,time,type,id,x,y,z,r,g,b,a,size), floats with 9 significant digits (each
 * float's exact value when read back).
 *   aot_dump FRAMES EVERY [BACKEND] > dump.csv */
#include <stdio.h>
#include <stdlib.h>

#include <psys/psys.h>

extern const psys_aot AOT_SYMBOL;

static int failed(psys_error* error) {
    if (!error) return 0;
    fprintf(stderr, "%s\n", psys_error_message(error));
    psys_error_free(error);
    return 1;
}

int main(int argc, char** argv) {
    psys_options options;
    psys_system* sys = NULL;
    psys_point* points = NULL;
    long frames, every, frame;
    size_t type, i, n, room = 0;
    if (argc < 3) return 2;
    frames = atol(argv[1]);
    every = atol(argv[2]);
    psys_options_init(&options);
    if (argc > 3) options.backend = argv[3];
    if (failed(psys_open_aot(&AOT_SYMBOL, &options, &sys))) return 1;
    printf("frame,time,type,id,x,y,z,r,g,b,a,size\n");
    for (frame = 1; frame <= frames; ++frame) {
        if (failed(psys_step(sys, 1.0 / 60))) return 1;
        for (type = 0; type < psys_type_count(sys); ++type) {
            psys_draw draw;
            if (failed(psys_get_draw(sys, type, &draw))) return 1;
        }
        if (frame % every) continue;
        for (type = 0; type < psys_type_count(sys); ++type) {
            if (failed(psys_read_points(sys, type, NULL, 0, &n))) return 1;
            if (n > room) {
                room = n;
                points = realloc(points, room * sizeof(psys_point));
            }
            if (failed(psys_read_points(sys, type, points, n, &n))) return 1;
            for (i = 0; i < n; ++i) {
                const psys_point* p = &points[i];
                printf("%ld,%.17g,%s,%u,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", frame, psys_time(sys),
                       psys_type_name(sys, type), (unsigned)p->id, p->position[0], p->position[1], p->position[2],
                       p->color[0], p->color[1], p->color[2], p->color[3], p->size);
            }
        }
    }
    free(points);
    psys_system_free(sys);
    return 0;
}
