// The Python module psys._psys over the C API (include/psys/psys.h): a System object per
// psys_system; errors become psys.CompileError (with the diagnostics) or psys.Error; the
// draw columns become NumPy arrays, copied from the system's memory on the CPU backends.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "psys/psys.h"
#include "python/draw.h"
#include "python/support.h"

namespace py = pybind11;

namespace {

using namespace psys::python;

class System {
public:
    explicit System(psys_system* s) : s_(s) {}
    ~System() { psys_system_free(s_); }
    // Frees the system now (a second close does nothing); every later call raises.
    void close() {
        auto held = hold();
        psys_system_free(s_);
        s_ = nullptr;
    }
    bool closed() const { return s_ == nullptr; }
    System(const System&) = delete;
    System& operator=(const System&) = delete;

    static std::unique_ptr<System> compile(const std::string& what, bool isSource, const std::string& name,
                                           const std::string& backend, const std::string& math, uint32_t seed,
                                           size_t capacity, unsigned threads, bool optimize,
                                           std::optional<std::string> jitCache, std::optional<std::string> libraryPath) {
        psys_options o;
        psys_options_init(&o);
        o.backend = backend.c_str();
        o.math = math.c_str();
        o.seed = seed;
        if (capacity) o.capacity = capacity;
        o.threads = threads;
        o.optimize = optimize;
        if (jitCache) o.jit_cache = jitCache->c_str();
        if (libraryPath) o.library_path = libraryPath->c_str();
        if (isSource) refuseNul(what, name);
        psys_system* s = nullptr;
        psys_error* e = nullptr;
        {
            py::gil_scoped_release unlocked;  // compiling takes a while: other Python threads run
            e = isSource ? psys_compile_string(what.c_str(), name.c_str(), &o, &s)
                         : psys_compile_file(what.c_str(), &o, &s);
        }
        check(e);
        return std::make_unique<System>(s);
    }

    // Steps without the GIL: other Python threads run meanwhile (another system's steps too).
    void step(double dt, int steps) {
        auto held = hold();
        if (steps < 0) raise(PyExc_ValueError, "step: steps is 0 or more, not " + std::to_string(steps));
        psys_system* s = open();
        psys_error* e = nullptr;
        {
            py::gil_scoped_release unlocked;
            for (int i = 0; i < steps && !e; ++i) e = psys_step(s, dt);
        }
        check(e);
    }
    // (instance: None for the effect's value, which sets every instance's; a handle for one's.)
    void set(const std::string& name, const py::object& values, const py::object& instance) {
        auto held = hold();
        std::vector<float> v = floats(values, "set");
        float current[4];
        int width = psys_get_extern(open(), name.c_str(), current);
        if (width < 0) raiseAs(unknownNameType(), "there is no extern `" + name + "`" + known(externs()));
        if (v.size() != static_cast<size_t>(width))
            raiseAs(valueTypeType(), "set: extern `" + name + "` is a " + externs()[name.c_str()].cast<std::string>() +
                                         " (" + std::to_string(width) + (width == 1 ? " number" : " numbers") +
                                         "), not " + reprOf(values));
        if (instance.is_none()) return check(psys_set_extern(s_, name.c_str(), v.data(), v.size()));
        check(psys_instance_set_extern(s_, instance.cast<psys_instance>(), name.c_str(), v.data(), v.size()));
    }
    py::object get(const std::string& name, const py::object& instance) const {
        auto held = hold();
        float v[4];
        int width = psys_get_extern(open(), name.c_str(), v);
        if (width < 0) raiseAs(unknownNameType(), "there is no extern `" + name + "`" + known(externs()));
        if (!instance.is_none() && psys_instance_get_extern(s_, instance.cast<psys_instance>(), name.c_str(), v) < 0)
            raise(PyExc_ValueError, "get: no instance " + py::repr(instance).cast<std::string>() + " is playing");
        if (width == 1) return py::float_(v[0]);
        return py::tuple(py::cast(std::vector<float>(v, v + width)));
    }
    void fire(const std::string& trigger, py::args args, py::kwargs kwargs) {
        auto held = hold();
        std::optional<uint64_t> instance;
        for (auto [key, value] : kwargs) {
            if (key.cast<std::string>() != "instance")
                raise(PyExc_TypeError, "fire() takes the trigger's arguments and instance=, not " + key.cast<std::string>() + "=");
            instance = value.cast<uint64_t>();
        }
        std::vector<float> all;
        for (py::handle a : args) {
            std::vector<float> v = floats(py::reinterpret_borrow<py::object>(a), "fire");
            all.insert(all.end(), v.begin(), v.end());
        }
        psys_input in{};
        bool found = false;
        for (size_t i = 0; !found && psys_trigger_info(open(), i, &in) == 0; ++i) found = trigger == in.name;
        if (!found) raiseAs(unknownNameType(), "there is no trigger `" + trigger + "`" + known(triggers()));
        if (all.size() != in.values)
            raiseAs(valueTypeType(), "fire: trigger `" + trigger + "` takes (" + in.type + "): " +
                                         std::to_string(in.values) + " numbers, not " + std::to_string(all.size()) +
                                         " in " + reprOf(args));
        if (instance) check(psys_instance_fire(s_, *instance, trigger.c_str(), all.data(), all.size()));
        else check(psys_fire(s_, trigger.c_str(), all.data(), all.size()));
    }
    // Instances (docs/embedding.md, "Instances"): handles are ints.
    static std::vector<float> transformOf(const py::object& transform) {
        if (transform.is_none()) return {};
        std::vector<float> m = floats(py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(transform)
                                          .attr("T").attr("ravel")(),
                                      "transform");
        if (m.size() != 16)
            raiseAs(valueTypeType(), "a transform is a 4×4 matrix (rows of columns, as NumPy prints it), not " +
                                         reprOf(transform));
        return m;
    }
    uint64_t play(const py::object& transform) {
        auto held = hold();
        std::vector<float> m = transformOf(transform);
        psys_instance h = 0;
        check(psys_play(open(), m.empty() ? nullptr : m.data(), &h));
        return h;
    }
    void move(uint64_t instance, const py::object& transform) {
        auto held = hold();
        std::vector<float> m = transformOf(transform);
        check(psys_instance_transform(open(), instance, m.empty() ? nullptr : m.data()));
    }
    void stop(uint64_t instance) {
        auto held = hold();
        check(psys_instance_stop(open(), instance));
    }
    void kill(uint64_t instance) {
        auto held = hold();
        check(psys_instance_kill(open(), instance));
    }
    // (speed=None reads it; a number sets it.)
    py::object speed(uint64_t instance, const py::object& value) {
        auto held = hold();
        if (value.is_none()) {
            float v = psys_instance_speed(open(), instance);
            if (v < 0) raise(PyExc_ValueError, "speed: no instance " + std::to_string(instance) + " is playing");
            return py::float_(v);
        }
        std::vector<float> v = floats(value, "speed");
        if (v.size() != 1) raise(PyExc_TypeError, "speed takes one number, not " + std::to_string(v.size()));
        check(psys_instance_set_speed(open(), instance, v[0]));
        return py::none();
    }
    void pause(uint64_t instance, bool paused) {
        auto held = hold();
        check(psys_instance_pause(open(), instance, paused ? 1 : 0));
    }
    bool paused(uint64_t instance) const {
        auto held = hold();
        int v = psys_instance_paused(open(), instance);
        if (v < 0) raise(PyExc_ValueError, "paused: no instance " + std::to_string(instance) + " is playing");
        return v == 1;
    }
    std::string life(uint64_t instance) const {
        auto held = hold();
        switch (psys_instance_life(open(), instance)) {
            case PSYS_PLAYING: return "playing";
            case PSYS_STOPPED: return "stopped";
            case PSYS_KILLED: return "killed";
            case PSYS_FINISHED: break;
        }
        return "finished";
    }
    size_t instanceCount() const {
        auto held = hold();
        return psys_instance_count(open());
    }
    std::vector<uint64_t> finishedInstances() const {
        auto held = hold();
        std::vector<uint64_t> out(psys_finished_instances(open(), nullptr, 0));
        psys_finished_instances(s_, out.data(), out.size());
        return out;
    }
    // Events (`notify "hit"(…)`): a step's notifications of one, n × width floats.
    py::array_t<float> events(const std::string& name) {
        auto held = hold();
        size_t n = 0, width = 0;
        psys_error* e = psys_read_events(open(), name.c_str(), nullptr, 0, &n, &width);
        if (e && std::string(psys_error_message(e)).find("there is no event") != std::string::npos) {
            std::string m = psys_error_message(e);
            psys_error_free(e);
            raiseAs(unknownNameType(), m);
        }
        check(e);
        py::array_t<float> out({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(width)});
        check(psys_read_events(s_, name.c_str(), out.mutable_data(), n, &n, &width));
        return out;
    }
    std::vector<std::string> eventNames() const {
        auto held = hold();
        std::vector<std::string> out;
        for (size_t i = 0; const char* name = psys_event_name(open(), i); ++i) out.emplace_back(name);
        return out;
    }
    void reserve(const py::object& type, size_t rows) {
        auto held = hold();
        check(psys_reserve(open(), typeOf(type), rows));
    }
    void prewarm(double seconds, double longest) {
        auto held = hold();
        psys_system* s = open();
        psys_error* e = nullptr;
        {
            py::gil_scoped_release unlocked;
            e = psys_prewarm(s, seconds, longest);
        }
        check(e);
    }
    void reset() {
        auto held = hold();
        check(psys_reset(open()));
    }
    void reload(std::optional<std::string> source) {
        auto held = hold();
        if (source) refuseNul(*source, "<string>");
        psys_system* s = open();
        psys_error* e = nullptr;
        {
            py::gil_scoped_release unlocked;  // compiling takes a while: other Python threads run
            e = psys_reload(s, source ? source->c_str() : nullptr);
        }
        check(e);
    }

    std::vector<std::string> types() const {
        auto held = hold();
        std::vector<std::string> out;
        psys_system* s = open();
        for (size_t t = 0; t < psys_type_count(s); ++t) out.push_back(psys_type_name(s, t));
        return out;
    }
    py::dict externs() const {
        auto held = hold();
        py::dict out;
        psys_input in;
        for (size_t i = 0; psys_extern_info(open(), i, &in) == 0; ++i) out[in.name] = in.type;
        return out;
    }
    py::dict triggers() const {
        auto held = hold();
        py::dict out;
        psys_input in;
        for (size_t i = 0; psys_trigger_info(open(), i, &in) == 0; ++i) out[in.name] = in.type;
        return out;
    }
    py::list warnings() const {
        auto held = hold();
        py::list out;
        psys_diagnostic d;
        for (size_t i = 0; psys_warning(open(), i, &d) == 0; ++i) out.append(diagnostic(d));
        return out;
    }

    size_t typeOf(const py::object& type) const {
        auto held = hold();
        if (py::isinstance<py::str>(type)) {
            int t = psys_type_index(open(), type.cast<std::string>().c_str());
            if (t < 0) {
                py::dict names;
                for (const std::string& name : types()) names[name.c_str()] = py::none();
                raiseAs(unknownNameType(), "there is no object type `" + type.cast<std::string>() + "`" + known(names));
            }
            return static_cast<size_t>(t);
        }
        size_t count = psys_type_count(open());
        long long index = 0;
        try {
            index = type.cast<long long>();
        } catch (const py::cast_error&) {
            raise(PyExc_TypeError, "a type is its name or its index, not " +
                                       py::str(py::type::of(type).attr("__name__")).cast<std::string>());
        }
        if (index < 0 || static_cast<unsigned long long>(index) >= count)
            raise(PyExc_IndexError, "there is no object type " + std::to_string(index) + ": the program's are " +
                                        (count ? "0 to " + std::to_string(count - 1) : std::string("none")));
        return static_cast<size_t>(index);
    }

    // The draw of a type, copied (python/draw.cpp): not views of the system's memory —
    // a step that grows a pool moves it and a reload frees it.
    py::dict columns(const py::object& type) {
        auto held = hold();
        return drawColumns(open(), typeOf(type));
    }
    py::dict points(const py::object& type) {
        auto held = hold();
        return drawPoints(open(), typeOf(type));
    }
    py::array_t<float> positions(const py::object& type) {
        auto held = hold();
        return drawPositions(open(), typeOf(type));
    }

    py::dict stats() const {
        auto held = hold();
        psys_stats st;
        check(psys_get_stats(open(), &st));
        py::dict out, types;
        out["steps"] = st.steps;
        out["rejected_steps"] = st.rejected_steps;
        out["rejected_externs"] = st.rejected_externs;
        out["invalid_emissions"] = st.invalid_emissions;
        out["non_finite_points"] = st.non_finite_points;
        out["update_seconds"] = st.update_seconds;
        out["emit_seconds"] = st.emit_seconds;
        out["create_seconds"] = st.create_seconds;
        out["draw_seconds"] = st.draw_seconds;
        out["fold_seconds"] = st.fold_seconds;
        for (size_t t = 0; t < psys_type_count(s_); ++t) {
            psys_type_stats ts;
            check(psys_get_type_stats(s_, t, &ts));
            py::dict d;
            d["live"] = ts.live;
            d["created"] = ts.created;
            d["killed"] = ts.killed;
            d["dropped"] = ts.dropped;
            d["unstable"] = ts.unstable;
            types[psys_type_name(s_, t)] = d;
        }
        out["types"] = types;
        return out;
    }

    double time() const {
        auto held = hold();
        return psys_time(open());
    }
    uint64_t stepCount() const {
        auto held = hold();
        return psys_step_count(open());
    }
    bool finished() const {
        auto held = hold();
        return psys_finished(open()) != 0;
    }

private:
    // The system held for a call: one call at a time on a system (the C API's rule), now
    // that step, prewarm and reload run without the GIL — a close() or a set() from another
    // Python thread waits for the step to end. Waiting, this thread lets the GIL go.
    std::unique_lock<std::recursive_mutex> hold() const {
        std::unique_lock<std::recursive_mutex> held(mutex_, std::try_to_lock);
        if (!held.owns_lock()) {
            py::gil_scoped_release unlocked;
            held.lock();
        }
        return held;
    }
    // The system, or the error of a call after close().
    psys_system* open() const {
        if (!s_) raise(PyExc_ValueError, "the system is closed");
        return s_;
    }
    // ": the program's are `a`, `b`" (or "s: it has none"), for an unknown name's message.
    static std::string known(const py::dict& names) {
        if (names.empty()) return ": it has none";
        std::string out = ": the program's are ";
        bool first = true;
        for (auto item : names) {
            out += (first ? "`" : ", `") + item.first.cast<std::string>() + "`";
            first = false;
        }
        return out;
    }

    psys_system* s_;
    mutable std::recursive_mutex mutex_;
};

}  // namespace

PYBIND11_MODULE(_psys, m) {
    m.doc() = "psys: particle systems compiled from .psys programs (docs/embedding.md)";
    m.attr("version") = psys_version();
    m.def("_set_errors", [](py::object compileError, py::object error, py::object unknownName, py::object valueType) {
        compileErrorType() = std::move(compileError);
        errorType() = std::move(error);
        unknownNameType() = std::move(unknownName);
        valueTypeType() = std::move(valueType);
    });
    m.def("_compile", &System::compile, py::arg("what"), py::arg("is_source"), py::arg("name"), py::arg("backend"),
          py::arg("math"), py::arg("seed"), py::arg("capacity"), py::arg("threads"), py::arg("optimize"),
          py::arg("jit_cache"), py::arg("library_path"));
    py::class_<System>(m, "System")
        .def("step", &System::step, py::arg("dt") = 1.0 / 60, py::arg("steps") = 1,
             "Advances every object by dt seconds, `steps` times.")
        .def("set", &System::set, py::arg("extern"), py::arg("value"), py::kw_only(), py::arg("instance") = py::none(),
             "Sets an extern: a number or a sequence; instance=H sets one instance's (else every instance's).")
        .def("get", &System::get, py::arg("extern"), py::kw_only(), py::arg("instance") = py::none(),
             "An extern's value (a float or a tuple); instance=H one instance's.")
        .def("fire", &System::fire, py::arg("trigger"),
             "Fires a trigger with its arguments (numbers or sequences); instance=H fires it on one instance.")
        .def("reload", &System::reload, py::arg("source") = py::none(),
             "Compiles the file again (or `source`); the running objects carry over.")
        .def("columns", &System::columns, py::arg("type"),
             "The draw columns, each copied into a read-only array of its own: visible, id, x y z, r g b a, size.")
        .def("points", &System::points, py::arg("type"), "The drawn points, copied: id, position, color, size.")
        .def("positions", &System::positions, py::arg("type"), "The drawn points' positions, copied: an n×3 array.")
        .def("stats", &System::stats)
        .def("play", &System::play, py::arg("transform") = py::none(),
             "Plays the effect again (an instanced program): a 4×4 affine transform (None: the identity); "
             "returns the instance's handle.")
        .def("move", &System::move, py::arg("instance"), py::arg("transform"), "Sets an instance's transform.")
        .def("stop", &System::stop, py::arg("instance"), "The instance emits no more; what it made lives on.")
        .def("kill", &System::kill, py::arg("instance"), "The instance's objects die at the next step.")
        .def("speed", &System::speed, py::arg("instance"), py::arg("value") = py::none(),
             "The instance's speed (seconds of its own a second of the system's, 0 to 100); with a value, sets it.")
        .def("pause", &System::pause, py::arg("instance"), py::arg("paused") = true,
             "Pauses the instance (paused=False resumes it): its objects stand still, its speed is kept.")
        .def("paused", &System::paused, py::arg("instance"), "Whether the instance is paused.")
        .def("life", &System::life, py::arg("instance"), "'playing', 'stopped', 'killed' or 'finished'.")
        .def_property_readonly("instance_count", &System::instanceCount)
        .def("finished_instances", &System::finishedInstances, "The instances that finished in the latest step.")
        .def("events", &System::events, py::arg("name"),
             "A step's notifications of an event (`notify`): an n × width array, its values in order (and, "
             "instanced, the instance's slot last).")
        .def_property_readonly("event_names", &System::eventNames)
        .def("reserve", &System::reserve, py::arg("type"), py::arg("rows"),
             "Room for `rows` objects of `type` made now: steps up to that many take nothing more.")
        .def("prewarm", &System::prewarm, py::arg("seconds"), py::arg("longest_step") = 0.1,
             "Runs `seconds` ahead at once in equal steps of at most `longest_step`, drawing nothing.")
        .def("reset", &System::reset, "Back to the start, with the same seed and the externs as set.")
        .def("close", &System::close, "Frees the system now; any later call raises ValueError.")
        .def_property_readonly("closed", &System::closed)
        .def("__enter__", [](py::object self) { return self; })
        .def("__exit__", [](System& s, py::args) { s.close(); })
        .def_property_readonly("types", &System::types)
        .def_property_readonly("externs", &System::externs)
        .def_property_readonly("triggers", &System::triggers)
        .def_property_readonly("warnings", &System::warnings)
        .def_property_readonly("time", &System::time)
        .def_property_readonly("step_count", &System::stepCount)
        .def_property_readonly("finished", &System::finished);
}
