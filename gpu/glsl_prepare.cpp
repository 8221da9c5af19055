// The GLSL backend's programs: what a launch of each kernel needs, compiled on the
// backend's thread (at once, or a part a frame: prepareSome) or on another thread with a
// shared context current (prepareShared: the viewer reloads without a frame compiling).
#include <algorithm>
#include <chrono>
#include <optional>
#include <stdexcept>
#include <thread>

#include <epoxy/gl.h>

#include "codegen_glsl/glsl_shaders.h"
#include "gpu/gl_context.h"
#include "gpu/gl_programs.h"
#include "gpu/glsl_backend.h"
#include "gpu/glsl_program.h"

namespace psys::gpu {

using rt::ColumnLayout;

namespace {

// The table columns a kernel writes: what stays on the GPU (state, exports, what is drawn:
// codegen_glsl::keptColumns) and what the host reads right after the launch (kill flags,
// emissions).
void writtenColumns(const ir::Kernel& kernel, const ColumnLayout& l, std::vector<int>& resident,
                    std::vector<int>& returned) {
    resident = codegen_glsl::keptColumns(kernel, l);
    for (const ir::Yield& y : kernel.yields) {
        switch (y.kind) {
            case ir::YieldKind::Kill: returned.push_back(ColumnLayout::kKill); break;
            case ir::YieldKind::EmitRate: returned.push_back(l.emitRate(y.index)); break;
            case ir::YieldKind::EmitCount: returned.push_back(l.emitCount(y.index)); break;
            default: break;
        }
    }
    std::sort(returned.begin(), returned.end());
    returned.erase(std::unique(returned.begin(), returned.end()), returned.end());
}

// The table columns a launch of `kernel` carries to the GPU: what its shader reads (a
// per-row clock's columns, the creation times always), and what it writes where
// rows keep their values (all but the kill flags, written for every row).
std::vector<bool> neededColumns(const ir::Kernel& kernel, const ColumnLayout& l, rt::Clock::Source now,
                                rt::Clock::Source dt, const std::vector<int>& resident, const std::vector<int>& returned) {
    std::vector<bool> needed(static_cast<size_t>(l.total), false);
    auto mark = [&needed](int first, int width) {
        for (int c = 0; c < width; ++c) needed[static_cast<size_t>(first + c)] = true;
    };
    mark(ColumnLayout::kCreated, 1);
    if (now == rt::Clock::Source::PerRow) mark(ColumnLayout::kNow, 1);
    if (dt == rt::Clock::Source::PerRow) mark(ColumnLayout::kDt, 1);
    for (const ir::Inst& i : kernel.insts()) {
        switch (i.op) {
            case ir::Op::Param: mark(l.paramOffset[static_cast<size_t>(i.attr)], i.type.width); break;
            case ir::Op::StateRead: mark(l.stateOffset[static_cast<size_t>(i.attr)], i.type.width); break;
            case ir::Op::ObjectId: mark(ColumnLayout::kIds, 1); break;
            default: break;
        }
    }
    for (const auto& p : l.parentColumns) mark(p.offset, p.width);
    for (int c : resident) mark(c, 1);
    for (int c : returned)
        if (c != ColumnLayout::kKill) mark(c, 1);
    return needed;
}

const ir::Kernel* uniformKernelOf(const ir::Object& object, const ir::Kernel& kernel) {
    auto served = ir::uniformFor(kernel.kind);
    return served ? object.kernel(*served) : nullptr;
}

}  // namespace

// Begun, and finished at once unless a plan is being prepared: then every program of it
// is begun first, so that a driver that compiles in parallel has them all (gl_programs.h).
unsigned GlslBackend::compile(const std::string& source, const std::string& what) {
    auto start = std::chrono::steady_clock::now();
    if (!compiler_) compiler_ = std::make_unique<ProgramCompiler>();
    unsigned program = compiler_->begin(source);
    if (preparing_)
        unfinished_.push_back({program, source, what});
    else
        compiler_->finish(program, source, what);
    ++kernels_;
    compileSeconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return program;
}

// What a launch of a rows kernel needs besides its GL program; its shader's source.
std::unique_ptr<GlslBackend::Program> GlslBackend::describeRows(const ir::Object& object, const ir::Kernel& kernel,
                                                                rt::Clock::Source now, rt::Clock::Source dt,
                                                                std::string& source, std::string& what) const {
    const ir::Kernel* uniform = uniformKernelOf(object, kernel);
    source = codegen_glsl::rowsShader(object, kernel, now, dt, uniform);
    what = object.name + "." + ir::kernelName(kernel.kind);
    auto p = std::make_unique<Program>();
    p->layout = rt::columnLayout(object, kernel);
    p->block = codegen_glsl::rowsBlock(kernel, uniform, p->layout);
    writtenColumns(kernel, p->layout, p->resident, p->returned);
    p->direct = codegen_glsl::directColumns(kernel, p->layout);
    p->inPlace.assign(static_cast<size_t>(p->layout.total) + 1, false);
    for (int c : p->direct) p->inPlace[static_cast<size_t>(c)] = true;
    p->needed = neededColumns(kernel, p->layout, now, dt,
                              p->resident, p->returned);  // (a dt since creation: computed, no column)
    p->pass = ir::kernelName(kernel.kind);
    p->counts = kernel.kind == ir::KernelKind::Render ||
                std::any_of(kernel.yields.begin(), kernel.yields.end(), [](const ir::Yield& y) {
                    return y.kind == ir::YieldKind::Kill || y.kind == ir::YieldKind::Unstable;
                });
    return p;
}

std::unique_ptr<GlslBackend::Program> GlslBackend::describeChildren(const ir::Object& object, const ir::Kernel& spawn,
                                                                    std::string& source, std::string& what) const {
    source = codegen_glsl::childrenShader(object, spawn);
    what = object.name + ".spawn" + std::to_string(spawn.site);
    auto p = std::make_unique<Program>();
    p->layout = rt::columnLayout(object, spawn);
    p->block = codegen_glsl::childrenBlock(object, spawn, p->layout);
    p->direct = codegen_glsl::directArguments(spawn);
    p->pass = "spawn";
    return p;
}

GlslBackend::Program& GlslBackend::rowsProgram(const ir::Object& object, const ir::Kernel& kernel,
                                               rt::Clock::Source now, rt::Clock::Source dt) {
    RowsKey key{&kernel, now, dt};
    {
        std::lock_guard lock(programsMutex_);
        if (auto it = rows_.find(key); it != rows_.end()) return *it->second;
    }
    // (described apart and then kept: a kernel the emitter refuses leaves no empty program)
    std::string source, what;
    std::unique_ptr<Program> p = describeRows(object, kernel, now, dt, source, what);
    p->program = compile(source, what);
    std::lock_guard lock(programsMutex_);
    return *(rows_[key] = std::move(p));
}

GlslBackend::Program& GlslBackend::childrenProgram(const ir::Object& object, const ir::Kernel& spawn) {
    {
        std::lock_guard lock(programsMutex_);
        if (auto it = children_.find(&spawn); it != children_.end()) return *it->second;
    }
    std::string source, what;
    std::unique_ptr<Program> p = describeChildren(object, spawn, source, what);
    p->program = compile(source, what);
    std::lock_guard lock(programsMutex_);
    return *(children_[&spawn] = std::move(p));
}

// On the thread that has the GL context, or on one that has a context sharing its objects
// current (gpu::SharedContextScope: the viewer's reloader). Elsewhere nothing can be done —
// GL calls on a thread without a context abort, and making the backend's current there
// would take it from its thread — and the programs compile when the System is made, or a
// part a frame (prepareSome).
void GlslBackend::prepare(const rt::Plan& plan) {
    if (std::this_thread::get_id() != owner_) {
        if (sharedContextCurrent()) prepareShared(plan);
        return;
    }
    if (context_) context_->makeCurrent();
    preparing_ = true;
    try {
        for (const auto& r : plan.rows) rowsProgram(*r.object, *r.kernel, r.now, r.dt);
        for (const auto& c : plan.children) childrenProgram(*c.object, *c.spawn);
    } catch (...) {
        preparing_ = false;
        throw;
    }
    preparing_ = false;
    auto start = std::chrono::steady_clock::now();
    std::vector<Unfinished> unfinished = std::move(unfinished_);
    unfinished_.clear();
    for (const Unfinished& u : unfinished) compiler_->finish(u.program, u.source, u.what);
    compileSeconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

bool GlslBackend::prepareSome(const rt::Plan& plan, double seconds) {
    if (std::this_thread::get_id() != owner_) return true;  // (as prepare: nothing can be done here)
    if (context_) context_->makeCurrent();
    auto start = std::chrono::steady_clock::now();
    bool any = false;
    auto spent = [&] {
        return any && std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= seconds;
    };
    auto have = [this](auto& map, const auto& key) {
        std::lock_guard lock(programsMutex_);
        return map.count(key) > 0;
    };
    for (const auto& r : plan.rows) {
        if (have(rows_, RowsKey{r.kernel, r.now, r.dt})) continue;
        if (spent()) return false;
        rowsProgram(*r.object, *r.kernel, r.now, r.dt);
        any = true;
    }
    for (const auto& c : plan.children) {
        if (have(children_, c.spawn)) continue;
        if (spent()) return false;
        childrenProgram(*c.object, *c.spawn);
        any = true;
    }
    return true;
}

// On another thread, with a context current that shares the backend's objects: the plan's
// programs begun (in parallel where the driver can) and finished there, complete before
// they are handed over (glFinish: another context sees a shared object's changes once they
// are done), then kept under the lock. One that does not compile is left for the
// backend's own thread, which says why as it always does.
void GlslBackend::prepareShared(const rt::Plan& plan) {
    std::vector<Made> made;
    ProgramCompiler compiler;
    for (const auto& r : plan.rows) {
        RowsKey key{r.kernel, r.now, r.dt};
        {
            std::lock_guard lock(programsMutex_);
            if (rows_.count(key)) continue;
        }
        Made m;
        m.key = key;
        m.program = describeRows(*r.object, *r.kernel, r.now, r.dt, m.source, m.what);
        made.push_back(std::move(m));
    }
    for (const auto& c : plan.children) {
        {
            std::lock_guard lock(programsMutex_);
            if (children_.count(c.spawn)) continue;
        }
        Made m;
        m.spawn = c.spawn;
        m.program = describeChildren(*c.object, *c.spawn, m.source, m.what);
        made.push_back(std::move(m));
    }
    for (Made& m : made) m.program->program = compiler.begin(m.source);
    std::vector<Made> finished;
    for (Made& m : made) {
        try {
            compiler.finish(m.program->program, m.source, m.what);
            finished.push_back(std::move(m));
        } catch (const std::exception&) {
            glDeleteProgram(m.program->program);
        }
    }
    glFinish();
    std::lock_guard lock(programsMutex_);
    for (Made& m : finished) {
        bool kept = m.key ? rows_.emplace(*m.key, std::move(m.program)).second
                          : children_.emplace(m.spawn, std::move(m.program)).second;
        if (!kept) glDeleteProgram(m.program->program);  // (made meanwhile on the backend's thread)
        else {
            ++kernels_;
            ++sharedPrograms_;
        }
    }
}

void GlslBackend::forget(const ir::Module& module) {
    std::lock_guard lock(programsMutex_);
    for (const ir::Object& o : module.objects)
        for (const ir::Kernel& k : o.kernels) {
            for (auto it = rows_.begin(); it != rows_.end();)
                if (std::get<0>(it->first) == &k) {
                    glDeleteProgram(it->second->program);
                    it = rows_.erase(it);
                } else {
                    ++it;
                }
            if (auto it = children_.find(&k); it != children_.end()) {
                glDeleteProgram(it->second->program);
                children_.erase(it);
            }
            forgetFold(k);
        }
}

}  // namespace psys::gpu
