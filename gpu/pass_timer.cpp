#include "gpu/pass_timer.h"

#include <epoxy/gl.h>

namespace psys::gpu {

PassTimer::~PassTimer() = default;

void PassTimer::release() {
    if (query_) glDeleteQueries(1, &query_);
    query_ = 0;
}

PassTimer::Scope::Scope(PassTimer* timer, const char* pass, size_t rows)
    : timer_(timer && timer->on() ? timer : nullptr), pass_(pass), rows_(rows) {
    if (!timer_) return;
    ++timer_->depth_;
    if (!timer_->query_) glGenQueries(1, &timer_->query_);
    glFinish();
    start_ = std::chrono::steady_clock::now();
    glBeginQuery(GL_TIME_ELAPSED, timer_->query_);
}

PassTimer::Scope::~Scope() {
    if (!timer_) return;
    glEndQuery(GL_TIME_ELAPSED);
    glFinish();
    double wall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
    GLuint64 ns = 0;
    glGetQueryObjectui64v(timer_->query_, GL_QUERY_RESULT, &ns);
    Time& t = timer_->times_[pass_];
    t.milliseconds += static_cast<double>(ns) * 1e-6;
    t.wallMilliseconds += wall;
    t.launches += 1;
    t.rows += rows_;
    --timer_->depth_;
}

}  // namespace psys::gpu
