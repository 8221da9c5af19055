// GLSL 4.50 shaders for a system's launches (rt/backend.h), from the same optimized IR
// kernels the CPU backends get.
//
// Interface of every compute shader (what a GPU backend binds):
//   binding 0, SSBO `Words`   uint w[]: every column of the launch, 32-bit words; a column
//                             holds one word per row (f32 as bits; u32; u8 widened to a
//                             word) or two (f64, low word first). Where column c's rows
//                             start is a word of the launch block.
//   binding 1, SSBO `Counts`  uint counts[4]: rows killed, rows unstable, rows drawn, rows
//                             visible but not finite (atomic adds of one per row: sums, the
//                             same whatever the order). A render shader marks its rows drawn.
//   binding 0, UBO  `Launch`  uvec4 L[]: the launch block (LaunchBlock): row count, clock,
//                             seed, draw, column offsets, externs and uniform values.
// One invocation per row, 64 to a work group, work groups in x then y (a grid of up to
// 65535 × 65535 groups).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ir/ir.h"
#include "rt/backend.h"
#include "rt/columns.h"

namespace psys::codegen_glsl {

// Where each input sits in the launch block, in 32-bit words. Values (externs, uniforms,
// the emitter's parameters, state and parent reads) take 4 words each, 16-byte aligned.
struct LaunchBlock {
    static constexpr uint32_t kCount = 0;       // rows (children) in the launch
    static constexpr uint32_t kFirstInvocation = 1;  // children: the emitter's first child in the launch
    static constexpr uint32_t kNow = 2;         // f64: now, for a uniform clock
    static constexpr uint32_t kDt = 4;          // f32: dt, for a uniform clock
    static constexpr uint32_t kFirst = 5;       // 1 while the rows are being created
    static constexpr uint32_t kSeed = 6;
    static constexpr uint32_t kDraw = 7;        // draw.index #0
    static constexpr uint32_t kFirstChild = 8;  // children: draw.index #1 of the first child
    static constexpr uint32_t kCreated = 10;    // children: f64, the emitter's creation time
    static constexpr uint32_t kObjectId = 12;   // children: the emitter's id
    static constexpr uint32_t kZero = 15;       // always 0: the shaders' zero constants (psys_zero)
    static constexpr uint32_t kColumns = 16;    // the columns' first words
    uint32_t columns = 0;  // how many: rows launches, the layout's columns and then the mask;
                           // children launches, one per component of the arguments
    uint32_t externs = 0, uniforms = 0, params = 0, state = 0, parents = 0;  // first words
    uint32_t externCount = 0, uniformCount = 0;
    uint32_t words = 0;                                                      // in all
};

constexpr uint32_t kWorkGroupSize = 64;

// Storage blocks a rows shader binds columns to in place (blocks 2, 3, …): GL's 16 storage
// blocks of a compute shader (llvmpipe's and NVIDIA's; GL 4.5 promises 8) less the
// launch's words and counts.
constexpr size_t kDirectSlots = 14;
// Buffer textures a rows shader reads columns through once the storage blocks are taken
// (GL 4.5 gives a compute shader at least 16 texture units).
constexpr size_t kTextureSlots = 16;

// The table columns a rows kernel writes and the pool keeps: its state, exports and what
// it draws (not kill flags or emissions, which the host reads right after the launch).
std::vector<int> keptColumns(const ir::Kernel& kernel, const rt::ColumnLayout& layout);
// The columns a rows shader reads and writes in place, each in its own GL buffer bound
// to storage block 2 + k, rather than copied into the launch's words and back: the kept
// columns, then the state it reads, the creation times, the mask (column `layout.total`),
// the parameters it reads, the ids and the parents' values (gathered on the GPU): the
// first kDirectSlots in storage blocks (what it writes among them), the next
// kTextureSlots, read only, through buffer textures (unit k − kDirectSlots). (Every
// table has a buffer for each of them: a parameter a kernel reads is kept.) The launch
// block's column word for one is the word its row `begin` sits at in the bound range.
std::vector<int> directColumns(const ir::Kernel& kernel, const rt::ColumnLayout& layout);
constexpr uint32_t kMaxGroupsX = 65535;

// The blocks hold the externs the kernels read (the first `externs` of the module's).
LaunchBlock rowsBlock(const ir::Kernel& kernel, const ir::Kernel* uniform, const rt::ColumnLayout& layout);
LaunchBlock childrenBlock(const ir::Object& object, const ir::Kernel& spawn, const rt::ColumnLayout& layout);

// A compute shader running `kernel` over rows (init, update, exports, render), for the
// clock sources a launch plan names. `uniform` is the kernel's uniform kernel, evaluated
// in the shader for each row where the clock is per row (else its values come in the block).
std::string rowsShader(const ir::Object& object, const ir::Kernel& kernel, rt::Clock::Source now,
                       rt::Clock::Source dt, const ir::Kernel* uniform);
// A children launch's uniform block (its emitters' blocks are in the launch's words):
// children in all, emitters, the first word of the first emitter's block, words a block.
struct LaunchRecords {
    static constexpr uint32_t kChildren = 0, kEmitters = 1, kFirstWord = 2, kWords = 3;
};
// The argument columns a children shader writes in place (storage blocks 2, 3, …): all
// of them where they fit, else none (they go in the launch's words).
std::vector<int> directArguments(const ir::Kernel& spawn);
// A compute shader running a spawn kernel once per child of each emitter of a launch:
// a launch block per emitter (childrenBlock), one after the other in the launch's words
// (LaunchRecords), each with its children's place among the launch's (kFirstInvocation)
// and its own column words for their arguments.

std::string childrenShader(const ir::Object& object, const ir::Kernel& spawn);

// The vertex and fragment shaders that draw points straight from render columns
// (visible, x y z, r g b a, size: DrawColumns), one vertex per row.
// The helpers the statements of emitBody call (psys_div, psys_pow, psys_zero, …), for a
// shader whose `lw(zeroWord)` holds 0.
std::string mathHelpers(uint32_t zeroWord);
// psys_narrow: a double to the nearest float, as C rounds it (mathHelpers holds it too).
std::string narrowHelper();

std::string drawVertexShader();
std::string drawFragmentShader();

// Every shader of a module, named and commented (`psysc --emit=glsl`): one per launch
// shape of its plan (rt::launchPlan), then the draw pair.
struct NamedShader {
    std::string name;   // "fountain.update.uniform.comp", …: the extension is the stage
    std::string source;
};
std::vector<NamedShader> moduleShaders(const rt::Plan& plan);

}  // namespace psys::codegen_glsl
