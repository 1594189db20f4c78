#pragma once
// Strict reading of the project's hand-edited JSON files (data/face,
// data/expression): every key is required unless read with a default, keys
// the code does not know are errors (they are usually typos), and each
// message names the file and the key path.
#include <array>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "emoface/common/error.h"

namespace emoface::expression::detail {

nlohmann::json read_json_file(const std::string& path, const char* module = "expression");

class JsonReader {
public:
    JsonReader(const nlohmann::json& value, std::string file, std::string path)
        : value_(value), file_(std::move(file)), path_(std::move(path)) {}

    bool has(const std::string& key) const { return value_.is_object() && value_.contains(key); }
    double number(const std::string& key);
    double number(const std::string& key, double fallback);
    int integer(const std::string& key);
    bool boolean(const std::string& key, bool fallback);
    std::string string(const std::string& key);
    template <std::size_t N>
    std::array<double, N> numbers(const std::string& key);
    std::vector<double> number_list(const std::string& key);
    JsonReader object(const std::string& key);
    // Elements of an array of objects.
    std::vector<JsonReader> objects(const std::string& key);
    const nlohmann::json& raw(const std::string& key);
    // Throws for keys that were not read ("_..." keys are comments).
    void finish() const;
    std::string where(const std::string& key) const;
    const std::string& file() const { return file_; }

private:
    const nlohmann::json& get(const std::string& key);
    [[noreturn]] void bad(const std::string& key, const char* expected) const;

    const nlohmann::json& value_;
    std::string file_;
    std::string path_;
    std::set<std::string> used_;
};

template <std::size_t N>
std::array<double, N> JsonReader::numbers(const std::string& key) {
    const nlohmann::json& v = get(key);
    if (!v.is_array() || v.size() != N) bad(key, N == 2 ? "an array of 2 numbers" : "an array of 3 numbers");
    std::array<double, N> out{};
    for (std::size_t i = 0; i < N; ++i) {
        if (!v[i].is_number()) bad(key, "an array of numbers");
        out[i] = v[i].get<double>();
    }
    return out;
}

}  // namespace emoface::expression::detail
