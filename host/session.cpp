#include "host/session.h"

#include <fmt/format.h>

#include <chrono>
#include <ostream>

#include "interp/interpreter.h"

namespace psys::host {

namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

void CompileResult::print(std::ostream& out, bool colour) const {
    if (diagnostics) diagnostics->print(out, colour);
}

std::string CompileResult::text() const { return diagnostics ? diagnostics->render(false) : std::string(); }

CompileResult compile(const std::string& path, const CompileOptions& options, std::optional<ir::Module>& module,
                      const std::string* text) {
    CompileResult result;
    result.sources = std::make_shared<SourceManager>();
    result.diagnostics = std::make_shared<DiagnosticEngine>(*result.sources);
    auto start = std::chrono::steady_clock::now();
    module = text ? compileText(path, *text, *result.sources, *result.diagnostics, options)
                  : compileFile(path, *result.sources, *result.diagnostics, options);
    result.seconds = secondsSince(start);
    result.ok = module.has_value();
    return result;
}

void chooseUnderTolerance(CompileOptions& options, tune::TuneOptions tune, const BackendChoice& runsOn,
                          std::shared_ptr<std::vector<tune::Choice>> choices) {
    tune.pipeline = options.pipeline;
    tune.pipeline.pass.relaxed |= runsOn.relaxesMaths();
    options.beforePasses = [tune, runsOn, choices](ir::Module& module, opt::PassErrors& messages) {
        bool wanted = false;
        for (const ir::Object& o : module.objects) wanted |= o.attributes.tolerance > 0;
        if (!wanted && !(tune.tolerance > 0)) return;
        std::shared_ptr<rt::Backend> trials;
        if (runsOn.name == "llvm")
            if (auto jit = makeBackend(runsOn)) trials = *jit;
        if (!trials) trials = std::make_shared<interp::Interpreter>();
        auto chosen = tune::chooseMethods(module, *trials, tune, messages);
        if (choices) *choices = std::move(chosen);
    };
}

SessionOptions Session::resolved(const SessionOptions& asked) {
    SessionOptions options = asked;
    options.compile.pipeline.pass.relaxed |= options.backend.relaxesMaths();
    options.compile.pipeline.pass.reloadable |= options.reloadable;
    if (!options.compile.beforePasses) chooseUnderTolerance(options.compile, options.tune, options.backend);
    return options;
}

std::unique_ptr<Session> Session::open(const std::string& path, const SessionOptions& asked, CompileResult& result,
                                       std::string& error, const std::string* text) {
    SessionOptions options = resolved(asked);
    std::optional<ir::Module> module;
    result = compile(path, options.compile, module, text);
    if (!module) return nullptr;
    return start(path, options, std::move(*module), error);
}

std::unique_ptr<Session> Session::start(const std::string& path, const SessionOptions& options, ir::Module module,
                                        std::string& error) {
    auto backend = makeBackend(options.backend);
    if (!backend) {
        error = backend.error;
        return nullptr;
    }
    if (auto tooLarge = rt::System::checkCapacity(module, options.system)) {
        error = *tooLarge;
        return nullptr;
    }
    if (auto refused = rt::System::checkBackend(module, **backend)) {
        error = *refused;
        return nullptr;
    }
    std::unique_ptr<Session> s(new Session());
    s->path_ = path;
    s->options_ = options;
    s->backend_ = *backend;
    s->system_ = std::make_unique<rt::System>(std::move(module), *s->backend_, options.system);
    return s;
}

Session::~Session() = default;

std::optional<std::string> Session::apply(const ExternSetting& setting) {
    // `true` and `false` are a bool's values only.
    for (const ir::Extern& e : system_->module().externs)
        if (e.name == setting.name && !e.type.isBool() && setting.words)
            return fmt::format("extern `{}` is a {}: it takes numbers, not true or false", e.name, rt::languageName(e));
    return system_->setExtern(setting.name, setting.values);
}

std::optional<std::string> Session::schedule(std::vector<TriggerFiring> firings, int lastFrame) {
    for (const TriggerFiring& f : firings) {
        if (auto error = system_->checkFiring(f.trigger, std::span<const float>(f.args))) return "--fire " + f.trigger + ": " + *error;
        if (lastFrame > 0 && f.frame > lastFrame)
            return fmt::format("--fire {}@{}: the run ends after frame {}", f.trigger, f.frame, lastFrame);
    }
    scheduled_ = std::move(firings);
    return std::nullopt;
}

std::optional<std::string> Session::fire(const TriggerFiring& firing) { return system_->fire(firing.trigger, firing.args); }

std::optional<std::string> Session::frame(int index, double dt, int steps) {
    for (const TriggerFiring& f : scheduled_)
        if (f.frame == index)
            if (auto error = fire(f)) return "--fire " + f.trigger + ": " + *error;
    auto start = std::chrono::steady_clock::now();
    std::optional<std::string> error;
    for (int s = 0; s < steps && !error; ++s) error = system_->step(dt);
    stepSeconds_ += secondsSince(start);
    return error;
}

Session::Candidate Session::compileCandidate(const std::string* text) const {
    Candidate c;
    c.compile = compile(path_, options_.compile, c.module, text);
    c.backend = backend_;
    if (c.module)
        if (auto refused = rt::System::checkBackend(*c.module, *c.backend)) {  // the running system goes on
            c.compile.diagnostics->error({}, *refused);
            c.compile.ok = false;
            c.module.reset();
        }
    if (c.module) {
        auto start = std::chrono::steady_clock::now();
        c.backend->prepare(rt::launchPlan(*c.module));
        c.prepareSeconds = secondsSince(start);
    }
    return c;
}

Session::Reload Session::adopt(Candidate candidate) {
    Reload out;
    out.compile = std::move(candidate.compile);
    if (!candidate.module) return out;  // the old system keeps running
    std::shared_ptr<rt::Backend> backend = candidate.backend ? candidate.backend : backend_;
    auto next = std::make_unique<rt::System>(std::move(*candidate.module), *backend, system_->options());
    out.report = next->carryOver(*system_);
    system_ = std::move(next);  // the old system goes before its backend
    backend_ = std::move(backend);
    return out;
}

Session::Reload Session::reload(const std::string* text) { return adopt(compileCandidate(text)); }

std::optional<std::string> Session::switchBackend(const BackendChoice& choice) {
    auto backend = makeBackend(choice);
    if (!backend) return backend.error;
    if (auto refused = rt::System::checkBackend(system_->module(), **backend)) return refused;
    auto next = std::make_unique<rt::System>(system_->module(), **backend, system_->options());
    next->carryOver(*system_);
    system_ = std::move(next);  // the old system goes before its backend
    backend_ = *backend;
    options_.backend = choice;
    return std::nullopt;
}

}  // namespace psys::host
