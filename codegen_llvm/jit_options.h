// What a user of the LLVM backend chooses and reads back, without LLVM's headers.
#pragma once

#include <string>

namespace psys::codegen_llvm {

// exact: the interpreter's float result bit for bit (no contraction into fused
//   multiply-adds, libm's scalar functions);
// fast: multiply-adds may fuse (one rounding instead of two) and sin, cos, tan, exp, log
//   and pow may use glibc's vector functions (libmvec, within 4 ulp of libm's).
enum class MathMode { Exact, Fast };

// What the loop vectorizer said about one loop.
struct VectorizeRemark {
    std::string function;
    bool vectorized;
    std::string message;
};

}  // namespace psys::codegen_llvm
