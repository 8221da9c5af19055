#include "rt/pool.h"

namespace psys::rt {

void Columns::define(const std::vector<ir::Type>& types) {
    types_ = types;
    offset_.clear();
    size_t n = 0;
    for (auto& t : types) {
        offset_.push_back(n);
        n += static_cast<size_t>(t.width);
    }
    columns_.assign(n, {});
}

void Columns::resize(size_t rows) {
    for (auto& c : columns_) c.resize(rows, 0.0f);
}

Value Columns::get(size_t i, size_t row) const {
    Value v;
    for (int c = 0; c < types_[i].width; ++c) v.f[static_cast<size_t>(c)] = columns_[offset_[i] + static_cast<size_t>(c)][row];
    return v;
}

void Columns::set(size_t i, size_t row, const Value& v) {
    for (int c = 0; c < types_[i].width; ++c) columns_[offset_[i] + static_cast<size_t>(c)][row] = v.f[static_cast<size_t>(c)];
}

Pool::Pool(const ir::Object& object, size_t capacity) : object_(&object), capacity_(capacity) {
    std::vector<ir::Type> types;
    for (auto& s : object.state) types.push_back(s.type);
    state.define(types);
    types.clear();
    for (auto& p : object.params) {
        paramColumn.push_back(p.kept ? static_cast<int>(types.size()) : -1);
        if (p.kept) types.push_back(p.type);
    }
    params.define(types);
    types.clear();
    for (auto& e : object.exports) types.push_back(e.type);
    exports.define(types);
    emitted.assign(object.emits.size(), {});
}

std::optional<uint32_t> Pool::allocate() {
    uint32_t row;
    if (!freeRows_.empty()) {
        row = freeRows_.back();
        freeRows_.pop_back();
    } else {
        if (rows() >= capacity_) return std::nullopt;
        row = static_cast<uint32_t>(rows());
        size_t n = rows() + 1;
        status_.resize(n, Status::Free);
        generation_.resize(n, 0);
        created.resize(n, 0);
        id.resize(n, 0);
        parent.resize(n);
        readers.resize(n, 0);
        updatable.resize(n, 0);
        for (auto& e : emitted) e.resize(n, 0);
        state.resize(n);
        params.resize(n);
        exports.resize(n);
    }
    status_[row] = Status::Alive;
    updatable[row] = 0;
    fresh.push_back(row);
    ++live_;
    readers[row] = 0;
    parent[row] = {};
    for (auto& e : emitted) e[row] = 0;
    return row;
}

void Pool::freeze(uint32_t row) {
    if (status_[row] != Status::Alive) return;
    status_[row] = Status::Frozen;
    updatable[row] = 0;
    --live_;
    ++frozen_;
}

void Pool::release(uint32_t row) {
    if (status_[row] == Status::Alive) --live_;
    else if (status_[row] == Status::Frozen) --frozen_;
    else return;
    status_[row] = Status::Free;
    updatable[row] = 0;
    ++generation_[row];
    freeRows_.push_back(row);
}

void Pool::beginStep() {
    for (uint32_t row : fresh)
        if (status_[row] == Status::Alive) updatable[row] = 1;
    fresh.clear();
}

}  // namespace psys::rt
