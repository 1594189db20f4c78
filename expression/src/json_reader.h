#pragma once
// The one strict reader of the project's JSON files (face.json, emotions and
// visemes, feature lines, wrinkle specs, key-map layouts, FDP files). Every
// key the code does not ask for is an error (it is usually a typo), every
// value is type- and range-checked, and every message has the data form of
// DESIGN.md, "Errors":
//   expression: data/expression/wrinkles.json: emotions.anger[2].dpeth: expected a known key (name, ...), found "dpeth"
// nlohmann-json's own exceptions never leave read_json_file/read_json_text:
// they become InputError naming the file.
//
// Use: read_json_file(path, [](JsonReader& root) { ...; return value; });
// read every key through the reader, call finish() on each object read (the
// root's is called for you). Keys starting with '_' and keys declared with
// comment() are free text for people.
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "emoface/common/error.h"

namespace emoface::expression::detail {

class JsonReader {
public:
    JsonReader(const nlohmann::json& value, std::string file, std::string path)
        : value_(&value), file_(std::move(file)), path_(std::move(path)) {}

    // --- keys of an object ---------------------------------------------------
    // Whether the object has `key` (and records `key` as one this reader knows).
    bool has(const std::string& key);
    // The value at `key`; a missing key is an error.
    JsonReader at(const std::string& key);
    // A key of free text for people (a string or a list of strings), ignored.
    void comment(const std::string& key);

    // Shorthands for at(key).as_...(); those with a fallback accept a missing key.
    double number(const std::string& key) { return at(key).as_number(); }
    double number(const std::string& key, double fallback) { return has(key) ? number(key) : fallback; }
    double number_in(const std::string& key, double min, double max) { return at(key).as_number_in(min, max); }
    double number_in(const std::string& key, double min, double max, double fallback) {
        return has(key) ? number_in(key, min, max) : fallback;
    }
    int integer(const std::string& key) { return at(key).as_integer(); }
    int integer_in(const std::string& key, int min, int max) { return at(key).as_integer_in(min, max); }
    bool boolean(const std::string& key, bool fallback) { return has(key) ? at(key).as_boolean() : fallback; }
    std::string string(const std::string& key) { return at(key).as_string(); }
    std::string string(const std::string& key, const std::string& fallback) {
        return has(key) ? string(key) : fallback;
    }
    template <std::size_t N>
    std::array<double, N> numbers(const std::string& key) { return at(key).as_numbers<N>(); }
    std::vector<double> number_list(const std::string& key) { return at(key).as_number_list(); }
    JsonReader object(const std::string& key) { return at(key).as_object(); }
    std::vector<JsonReader> objects(const std::string& key);

    // --- this value ----------------------------------------------------------
    bool is_string() const { return value_->is_string(); }
    bool is_array() const { return value_->is_array(); }
    bool is_object() const { return value_->is_object(); }
    double as_number() const;  // finite
    double as_number_in(double min, double max) const;
    int as_integer() const;
    int as_integer_in(int min, int max) const;
    bool as_boolean() const;
    std::string as_string() const;
    template <std::size_t N>
    std::array<double, N> as_numbers() const;  // [a, b, ...], N finite numbers
    std::vector<double> as_number_list() const;
    JsonReader as_object() const;  // this value, checked to be an object
    // The elements of an array, each at "path[i]".
    std::vector<JsonReader> elements() const;
    // The entries of an object whose keys are data (feature-point ids, emotion
    // names), comment keys left out; all count as read.
    std::vector<std::pair<std::string, JsonReader>> entries();

    // Every key of this object was asked for, or is a comment; else an error
    // listing the known keys.
    void finish() const;

    // Throws the data-form InputError at this value: "expected <expected>,
    // found <this value>" (or `found` when given).
    [[noreturn]] void fail(std::string_view expected) const;
    [[noreturn]] void fail(std::string_view expected, std::string_view found) const;

    const std::string& file() const { return file_; }
    const std::string& path() const { return path_; }
    FileLoc loc() const { return {file_, 0, path_}; }
    const nlohmann::json& raw() const { return *value_; }

private:
    std::string child_path(const std::string& key) const;
    void expect_object() const;

    const nlohmann::json* value_;
    std::string file_;
    std::string path_;
    std::vector<std::string> known_;  // keys asked for, in the order asked (for messages)
    std::vector<std::string> comments_;
};

// "parent.key", the key quoted when it is not a plain name ("feature_points.\"2.1\"").
std::string json_key_path(const std::string& parent, const std::string& key);

// A JSON value as a message's "found" part: strings quoted, long values cut.
std::string describe_json(const nlohmann::json& value);

// Parses JSON text (comments allowed) or fails with the data form, the line
// of the syntax error included.
nlohmann::json parse_json(std::string_view text, const std::string& file);
std::string read_text_file(const std::string& path);  // InputError when it cannot be opened

// Parses `text`, hands the root to `read` and checks the root's keys; turns
// any nlohmann-json exception that escapes `read` into an InputError that
// names `file`, so none reaches the caller.
template <typename Read>
auto read_json_text(std::string_view text, const std::string& file, Read&& read) {
    const nlohmann::json doc = parse_json(text, file);
    try {
        JsonReader root(doc, file, "");
        if constexpr (std::is_void_v<decltype(read(root))>) {
            read(root);
            root.finish();
        } else {
            auto result = read(root);
            root.finish();
            return result;
        }
    } catch (const nlohmann::json::exception& e) {
        emoface::fail_data("expression", FileLoc{file, 0, ""}, "well-typed JSON values", e.what());
    }
}

template <typename Read>
auto read_json_file(const std::string& path, Read&& read) {
    return read_json_text(read_text_file(path), path, std::forward<Read>(read));
}

template <std::size_t N>
std::array<double, N> JsonReader::as_numbers() const {
    static const std::string expected = "an array of " + std::to_string(N) + " numbers";
    if (!value_->is_array() || value_->size() != N) fail(expected);
    std::array<double, N> out{};
    for (std::size_t i = 0; i < N; ++i) {
        const nlohmann::json& v = (*value_)[i];
        if (!v.is_number() || !std::isfinite(v.get<double>())) fail(expected);
        out[i] = JsonReader(v, file_, path_ + "[" + std::to_string(i) + "]").as_number();
    }
    return out;
}

}  // namespace emoface::expression::detail
