// Internal to gpu/: what the GLSL backend keeps for neighbour folds (gpu/gl_fold.cpp) —
// the grid's programs and buffers, and a program per pair kernel.
#pragma once

#include <epoxy/gl.h>

#include <map>
#include <utility>

#include "codegen_glsl/glsl_fold.h"
#include "gpu/glsl_backend.h"

namespace psys::gpu {

struct FoldWork {
    unsigned count = 0, scan = 0, scatter = 0, sort = 0, place = 0;  // programs
    std::map<const ir::Kernel*, std::pair<unsigned, codegen_glsl::FoldShader>> folds;
    enum { kSelf, kOther, kBucketOf, kCounts, kStart, kGroups, kCursor, kSorted, kPlaced, kResults, kWords, kBuffers };
    unsigned buffers[kBuffers] = {};
    size_t capacity[kBuffers] = {};
    unsigned params = 0, upload = 0;  // (upload: what the host sends into kWords goes through it: sendThrough)
    ~FoldWork() {
        for (unsigned p : {count, scan, scatter, sort, place})
            if (p) glDeleteProgram(p);
        for (auto& [k, f] : folds) glDeleteProgram(f.first);
        glDeleteBuffers(kBuffers, buffers);
        if (params) glDeleteBuffers(1, &params);
        if (upload) glDeleteBuffers(1, &upload);
    }
};

}  // namespace psys::gpu
