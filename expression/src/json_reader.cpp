#include "json_reader.h"

#include <fstream>
#include <sstream>

namespace emoface::expression::detail {

nlohmann::json read_json_file(const std::string& path, const char* module) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail<InputError>("{}: cannot open {}", module, path);
    std::ostringstream text;
    text << in.rdbuf();
    try {
        return nlohmann::json::parse(text.str());
    } catch (const nlohmann::json::parse_error& e) {
        // e.byte locates the error; the library's own text follows.
        fail<InputError>("{}: {}: not valid JSON (at byte {}): {}", module, path, e.byte, e.what());
    }
}

std::string JsonReader::where(const std::string& key) const {
    return path_.empty() ? key : path_ + "." + key;
}

void JsonReader::bad(const std::string& key, const char* expected) const {
    fail<InputError>("expression: {}: \"{}\" must be {}", file_, where(key), expected);
}

const nlohmann::json& JsonReader::get(const std::string& key) {
    if (!value_.is_object()) fail<InputError>("expression: {}: \"{}\" must be an object", file_, path_);
    auto it = value_.find(key);
    if (it == value_.end()) fail<InputError>("expression: {}: missing key \"{}\"", file_, where(key));
    used_.insert(key);
    return *it;
}

const nlohmann::json& JsonReader::raw(const std::string& key) { return get(key); }

double JsonReader::number(const std::string& key) {
    const nlohmann::json& v = get(key);
    if (!v.is_number()) bad(key, "a number");
    return v.get<double>();
}

double JsonReader::number(const std::string& key, double fallback) {
    if (!has(key)) return fallback;
    return number(key);
}

int JsonReader::integer(const std::string& key) {
    const nlohmann::json& v = get(key);
    if (!v.is_number_integer()) bad(key, "an integer");
    return v.get<int>();
}

bool JsonReader::boolean(const std::string& key, bool fallback) {
    if (!has(key)) return fallback;
    const nlohmann::json& v = get(key);
    if (!v.is_boolean()) bad(key, "true or false");
    return v.get<bool>();
}

std::string JsonReader::string(const std::string& key) {
    const nlohmann::json& v = get(key);
    if (!v.is_string()) bad(key, "a string");
    return v.get<std::string>();
}

std::vector<double> JsonReader::number_list(const std::string& key) {
    const nlohmann::json& v = get(key);
    if (!v.is_array()) bad(key, "an array of numbers");
    std::vector<double> out;
    for (const auto& e : v) {
        if (!e.is_number()) bad(key, "an array of numbers");
        out.push_back(e.get<double>());
    }
    return out;
}

JsonReader JsonReader::object(const std::string& key) {
    const nlohmann::json& v = get(key);
    if (!v.is_object()) bad(key, "an object");
    return JsonReader(v, file_, where(key));
}

std::vector<JsonReader> JsonReader::objects(const std::string& key) {
    const nlohmann::json& v = get(key);
    if (!v.is_array()) bad(key, "an array of objects");
    std::vector<JsonReader> out;
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (!v[i].is_object()) bad(key, "an array of objects");
        out.emplace_back(v[i], file_, where(key) + "[" + std::to_string(i) + "]");
    }
    return out;
}

void JsonReader::finish() const {
    if (!value_.is_object()) return;
    for (auto it = value_.begin(); it != value_.end(); ++it) {
        if (!it.key().empty() && it.key()[0] == '_') continue;
        if (used_.count(it.key()) == 0)
            fail<InputError>("expression: {}: unknown key \"{}\"", file_, where(it.key()));
    }
}

}  // namespace emoface::expression::detail
