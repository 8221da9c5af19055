// What a user of the LLVM backend chooses, without LLVM's headers.
#pragma once

namespace psys::codegen_llvm {

// exact: the interpreter's float result bit for bit (no contraction into fused
//   multiply-adds, libm's scalar functions);
// fast: multiply-adds may fuse (one rounding instead of two) and sin, cos, tan, exp, log
//   and pow may use glibc's vector functions (libmvec, within 4 ulp of libm's).
enum class MathMode { Exact, Fast };

}  // namespace psys::codegen_llvm
