#include "reloader.h"

#include <cctype>
#include <filesystem>
#include <fstream>

#include "gpu/gl_context.h"
#include "host/large_stack.h"

namespace psys::viewer {

namespace {

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

}  // namespace

Reloader::~Reloader() {
    if (worker_.joinable()) worker_.join();
}

void Reloader::saved(Clock::time_point when) {
    if (worker_.joinable()) {  // (a candidate being prepared a slice a frame does not wait for it)
        if (!pending_) pending_ = when;
        return;
    }
    start(when);
}

namespace {

// A file with nothing but white space, or none at all, is not a program to adopt.
std::optional<Reloader::Outcome::Kind> emptyOrGone(const std::string& path) {
    std::error_code error;
    if (!std::filesystem::exists(path, error)) return Reloader::Outcome::Kind::Vanished;
    std::ifstream in(path);
    for (char c; in.get(c);)
        if (!std::isspace(static_cast<unsigned char>(c))) return std::nullopt;
    return in.bad() ? std::nullopt : std::optional(Reloader::Outcome::Kind::Empty);
}

}  // namespace

void Reloader::start(Clock::time_point when) {
    savedAt_ = when;
    compiled_ = prepared_ = interim_ = false;
    std::string path = session_.path();
    host::SessionOptions options = session_.options();
    std::shared_ptr<rt::Backend> backend = session_.backendHandle();
    // The compile recurses as deep as the program nests: on a large stack, as the main thread's work.
    worker_ = std::thread([this, path, options, backend] { host::runWithLargeStack([&] { return work(path, options, backend); }); });
}

int Reloader::work(const std::string& path, const host::SessionOptions& options, std::shared_ptr<rt::Backend> backend) {
    if (auto kept = emptyOrGone(path)) {  // nothing to compile: the running system stays
        std::lock_guard lock(mutex_);
        kept_ = kept;
        compiled_ = prepared_ = true;
        return 0;
    }
    {
        host::Session::Candidate candidate;
        candidate.compile = host::compile(path, options.compile, candidate.module);
        candidate.backend = backend;
        {
            std::lock_guard lock(mutex_);
            compile_ = candidate.compile;
            if (candidate.module) interimModule_ = *candidate.module;
            compiled_ = true;
        }
        if (candidate.module) {
            auto start = Clock::now();
            // With a shared context current, a GLSL backend compiles its programs here.
            if (context_ && backend->name() == "glsl" && context_->makeCurrent()) {
                struct Released {  // (whatever prepare does, the context goes back)
                    WorkerContext* context;
                    ~Released() { context->release(); }
                } released{context_};
                gpu::SharedContextScope shared;
                backend->prepare(rt::launchPlan(*candidate.module));
            } else {
                backend->prepare(rt::launchPlan(*candidate.module));
            }
            candidate.prepareSeconds = secondsSince(start);
        }
        std::lock_guard lock(mutex_);
        candidate_ = std::move(candidate);
        prepared_ = true;
    }
    return 0;
}

void Reloader::finish() {
    worker_.join();
    if (pending_) {
        Clock::time_point when = *pending_;
        pending_.reset();
        start(when);
    }
}

std::optional<Reloader::Outcome> Reloader::poll() {
    if (!busy()) return std::nullopt;
    std::unique_lock lock(mutex_);
    if (prepared_ && kept_) {
        Outcome out{*kept_, {}, std::nullopt, secondsSince(savedAt_), 0};
        kept_.reset();
        lock.unlock();
        finish();
        return out;
    }
    if (prepared_ && !ready_) {
        ready_ = std::move(candidate_);
        readySaved_ = savedAt_;
        prepared_ = false;
        lock.unlock();
        finish();
        if (ready_->module) readyPlan_ = rt::launchPlan(*ready_->module);
        readySlices_ = 0;
        lock.lock();
    }
    if (ready_) {
        lock.unlock();
        if (ready_->module) {  // the rest of its preparing, a slice this frame
            auto start = Clock::now();
            size_t kernels = ready_->backend->report().kernels;
            bool done = ready_->backend->prepareSome(readyPlan_, sliceSeconds);
            ready_->prepareSeconds += secondsSince(start);
            readySlices_ += ready_->backend->report().kernels != kernels;
            if (!done) return std::nullopt;
        }
        host::Session::Candidate candidate = std::move(*ready_);
        ready_.reset();
        Clock::time_point saved = readySaved_;
        Outcome out{candidate.module ? Outcome::Kind::Adopted : Outcome::Kind::Failed, {}, std::nullopt, 0,
                    candidate.prepareSeconds, readySlices_};
        host::Session::Reload r = session_.adopt(std::move(candidate));
        out.compile = std::move(r.compile);
        out.report = std::move(r.report);
        out.latencySeconds = secondsSince(saved);
        return out;
    }
    // The JIT is still compiling: after a while, the new system runs on the interpreter.
    bool jit = session_.backend().name() == "llvm";
    if (!compiled_ || !interimModule_ || interim_ || !jit || secondsSince(savedAt_) < interimAfterSeconds)
        return std::nullopt;
    host::Session::Candidate interim;
    interim.compile = compile_;
    interim.module = std::move(interimModule_);
    interimModule_.reset();
    lock.unlock();
    auto interpreter = host::makeBackend({"interp", "fast"});
    if (!interpreter) return std::nullopt;
    interim.backend = *interpreter;
    interim_ = true;
    Outcome out{Outcome::Kind::Interim, {}, std::nullopt, 0, 0};
    host::Session::Reload r = session_.adopt(std::move(interim));
    out.compile = std::move(r.compile);
    out.report = std::move(r.report);
    out.latencySeconds = secondsSince(savedAt_);
    return out;
}

}  // namespace psys::viewer
