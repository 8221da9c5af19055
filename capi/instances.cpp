// The C API's instances and events (include/psys/psys.h, "Instances", "Events"):
// rt::System's, checked for null arguments and with its refusals as errors.
#include <algorithm>
#include <optional>
#include <span>

#include <fmt/format.h>

#include "capi/error.h"
#include "capi/handle.h"

using psys::capi::guarded;
using psys::capi::nullArgument;
using psys::capi::orError;
namespace rt = psys::rt;

namespace {

std::span<const float> transformOf(const float* transform) {
    return transform ? std::span<const float>(transform, 16) : std::span<const float>();
}

}  // namespace

extern "C" {

psys_error* psys_play(psys_system* s, const float* transform, psys_instance* out) {
    if (!s) return nullArgument("psys_play", "the system");
    if (!out) return nullArgument("psys_play", "the place for the instance (out)");
    return guarded("psys_play", [&] {
        rt::InstanceHandle h = 0;
        psys_error* e = orError("psys_play", s->system().play(transformOf(transform), h));
        if (!e) *out = h;
        return e;
    });
}

psys_error* psys_instance_transform(psys_system* s, psys_instance instance, const float* transform) {
    if (!s) return nullArgument("psys_instance_transform", "the system");
    return guarded("psys_instance_transform", [&] {
        return orError("psys_instance_transform", s->system().setTransform(instance, transformOf(transform)));
    });
}

psys_error* psys_instance_stop(psys_system* s, psys_instance instance) {
    if (!s) return nullArgument("psys_instance_stop", "the system");
    return guarded("psys_instance_stop", [&] { return orError("psys_instance_stop", s->system().stop(instance)); });
}

psys_error* psys_instance_kill(psys_system* s, psys_instance instance) {
    if (!s) return nullArgument("psys_instance_kill", "the system");
    return guarded("psys_instance_kill", [&] { return orError("psys_instance_kill", s->system().kill(instance)); });
}

psys_error* psys_instance_fire(psys_system* s, psys_instance instance, const char* trigger, const float* args,
                               size_t count) {
    if (!s) return nullArgument("psys_instance_fire", "the system");
    if (!trigger) return nullArgument("psys_instance_fire", "the trigger's name");
    if (!args && count) return nullArgument("psys_instance_fire", "the arguments");
    return guarded("psys_instance_fire", [&] {
        return orError("psys_instance_fire", s->system().fire(trigger, std::span<const float>(args, count), instance));
    });
}

psys_error* psys_instance_set_extern(psys_system* s, psys_instance instance, const char* name, const float* values,
                                     size_t count) {
    if (!s) return nullArgument("psys_instance_set_extern", "the system");
    if (!name) return nullArgument("psys_instance_set_extern", "the extern's name");
    if (!values && count) return nullArgument("psys_instance_set_extern", "the values");
    return guarded("psys_instance_set_extern", [&] {
        int handle = s->system().externHandle(name);
        if (handle < 0) return orError("psys_instance_set_extern", fmt::format("there is no extern `{}`", name));
        return orError("psys_instance_set_extern",
                       s->system().setInstanceExtern(instance, handle, std::span<const float>(values, count)));
    });
}

int psys_instance_get_extern(const psys_system* s, psys_instance instance, const char* name, float values[4]) {
    if (!s || !name) return -1;
    int handle = s->system().externHandle(name);
    std::optional<rt::Value> v = s->system().instanceExtern(instance, handle);
    if (!v) return -1;
    int width = s->system().module().externs[static_cast<size_t>(handle)].type.width;
    for (int c = 0; values && c < width; ++c) values[c] = v->f[static_cast<size_t>(c)];
    return width;
}

psys_error* psys_instance_set_speed(psys_system* s, psys_instance instance, float speed) {
    if (!s) return nullArgument("psys_instance_set_speed", "the system");
    return guarded("psys_instance_set_speed",
                   [&] { return orError("psys_instance_set_speed", s->system().setSpeed(instance, speed)); });
}

float psys_instance_speed(const psys_system* s, psys_instance instance) {
    std::optional<float> v = s ? s->system().speed(instance) : std::nullopt;
    return v ? *v : -1.0f;
}

psys_error* psys_instance_pause(psys_system* s, psys_instance instance, int paused) {
    if (!s) return nullArgument("psys_instance_pause", "the system");
    return guarded("psys_instance_pause",
                   [&] { return orError("psys_instance_pause", s->system().pause(instance, paused != 0)); });
}

int psys_instance_paused(const psys_system* s, psys_instance instance) {
    std::optional<bool> v = s ? s->system().paused(instance) : std::nullopt;
    return v ? static_cast<int>(*v) : -1;
}

psys_life psys_instance_life(const psys_system* s, psys_instance instance) {
    if (!s) return PSYS_FINISHED;
    switch (s->system().life(instance)) {
        case rt::InstanceLife::Playing: return PSYS_PLAYING;
        case rt::InstanceLife::Stopped: return PSYS_STOPPED;
        case rt::InstanceLife::Killed: return PSYS_KILLED;
        case rt::InstanceLife::Finished: break;
    }
    return PSYS_FINISHED;
}

size_t psys_instance_count(const psys_system* s) { return s ? s->system().instanceCount() : 0; }

size_t psys_finished_instances(const psys_system* s, psys_instance* out, size_t max) {
    if (!s) return 0;
    std::span<const rt::InstanceHandle> finished = s->system().finishedInstances();
    for (size_t i = 0; i < finished.size() && i < max && out; ++i) out[i] = finished[i];
    return finished.size();
}

size_t psys_event_count(const psys_system* s) { return s ? s->eventNames.size() : 0; }

const char* psys_event_name(const psys_system* s, size_t index) {
    return s && index < s->eventNames.size() ? s->eventNames[index].c_str() : nullptr;
}

psys_error* psys_read_events(psys_system* s, const char* name, float* out, size_t max, size_t* count, size_t* width) {
    if (!s) return nullArgument("psys_read_events", "the system");
    if (!name) return nullArgument("psys_read_events", "the event's name");
    if (!out && max) return nullArgument("psys_read_events", "the events (out)");
    return guarded("psys_read_events", [&]() -> psys_error* {
        size_t w = 0;
        if (psys_error* e = orError("psys_read_events", s->system().events(name, s->events, w))) return e;
        const size_t n = w ? s->events.size() / w : 0;
        if (count) *count = n;
        if (width) *width = w;
        if (out) std::copy_n(s->events.begin(), std::min(n, max) * w, out);
        return nullptr;
    });
}

}  // extern "C"
