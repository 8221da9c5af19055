#include "lsp/params.h"

namespace psys::lsp {

namespace {

std::string shortDump(const nlohmann::json& v) {
    std::string s = v.dump();
    return s.size() > 40 ? s.substr(0, 37) + "..." : s;
}

}  // namespace

void Field::refuse(const std::string& expected) const {
    std::string name = path_.empty() ? "the params" : "`" + path_ + "`";
    throw InvalidParams(name + " must be " + expected + ", not " + shortDump(*value_));
}

Field Field::operator[](const char* key) const {
    auto member = get(key);
    if (!member) throw InvalidParams("`" + (path_.empty() ? std::string() : path_ + ".") + key + "` is missing");
    return *member;
}

std::optional<Field> Field::get(const char* key) const {
    if (!value_->is_object()) refuse("an object");
    auto it = value_->find(key);
    if (it == value_->end() || it->is_null()) return std::nullopt;
    return Field(*it, path_.empty() ? key : path_ + "." + key);
}

std::string Field::string() const {
    if (!value_->is_string()) refuse("a string");
    return value_->get<std::string>();
}

const nlohmann::json& Field::array() const {
    if (!value_->is_array()) refuse("an array");
    return *value_;
}

const nlohmann::json& Field::object() const {
    if (!value_->is_object()) refuse("an object");
    return *value_;
}

bool Field::boolean() const {
    if (!value_->is_boolean()) refuse("true or false");
    return value_->get<bool>();
}

}  // namespace psys::lsp
