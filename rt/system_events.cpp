// Events (`notify "hit"(pos, speed)`: docs/language.md, "Events"): each notification is an
// object of its event's type (ir::eventType) that lives until the end of the next step's
// update, so after a step the alive ones are that step's (and those of triggers fired
// since). Reading them is reading those rows' parameters, on any backend.
#include <fmt/format.h>

#include "rt/system.h"
#include "rt/system_state.h"

namespace psys::rt {

std::vector<std::string> System::eventNames() const {
    std::vector<std::string> out;
    for (const ir::Object& o : state_->module.objects)
        if (ir::isEventType(o.name)) out.push_back(o.name.substr(ir::eventType("").size()));
    return out;
}

std::optional<std::string> System::events(std::string_view name, std::vector<float>& out, size_t& width) {
    detail::State& s = *state_;
    out.clear();
    width = 0;
    const int type = s.module.objectIndex(ir::eventType(name));
    if (type < 0) {
        std::string known;
        for (const std::string& n : eventNames()) known += (known.empty() ? "\"" : ", \"") + n + "\"";
        return fmt::format("there is no event \"{}\" ({})", name,
                           known.empty() ? std::string("the program notifies none") : "its events are " + known);
    }
    finish();  // a device's kills of the last step, counted
    const Pool& pool = s.pools[static_cast<size_t>(type)];
    // Each value's columns (an instanced program's hidden instance last, as its slot).
    std::vector<Buffer> columns;
    for (size_t p = 0; p < pool.object().params.size(); ++p) {
        const int column = pool.paramColumn[p];
        for (int c = 0; c < pool.object().params[p].type.width; ++c)
            columns.push_back(column < 0 ? Buffer{} : pool.params.column(static_cast<size_t>(column), static_cast<size_t>(c)));
    }
    width = columns.size();
    const size_t rows = pool.rows();
    std::vector<float> column(rows);
    std::vector<uint32_t> alive;
    for (uint32_t r = 0; r < rows; ++r)
        if (pool.status(r) == Status::Alive) alive.push_back(r);
    out.assign(alive.size() * width, 0.0f);
    for (size_t k = 0; k < width; ++k) {
        if (!columns[k].valid() || rows == 0) continue;
        s.memory.read(columns[k], 0, rows, column.data());
        for (size_t e = 0; e < alive.size(); ++e) out[e * width + k] = column[alive[e]];
    }
    return std::nullopt;
}

}  // namespace psys::rt
