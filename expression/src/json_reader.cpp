#include "json_reader.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace emoface::expression::detail {
namespace {

constexpr const char* kModule = "expression";

bool is_comment_key(const std::string& key) { return !key.empty() && key[0] == '_'; }

// A key as it appears in a path: plain when it is a name or a number, quoted
// when it holds dots or other marks ("feature_points."2.1".vertex").
std::string path_key(const std::string& key) {
    const bool plain = !key.empty() &&
                       std::all_of(key.begin(), key.end(), [](char c) {
                           return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                                  c == '_' || c == '-';
                       });
    return plain ? key : "\"" + key + "\"";
}

// The text after "line L, column C: " in nlohmann's parse message.
std::string syntax_detail(const std::string& what) {
    const auto column = what.find("column ");
    const auto colon = column == std::string::npos ? std::string::npos : what.find(": ", column);
    return colon == std::string::npos ? what : what.substr(colon + 2);
}

}  // namespace

std::string describe_json(const nlohmann::json& value) {
    constexpr std::size_t kMax = 40;
    std::string text = value.dump();
    if (text.size() > kMax) text = text.substr(0, kMax) + "...";
    return text;
}

std::string read_text_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in)
        fail_data(kModule, FileLoc{path, 0, ""}, "a readable file",
                  std::filesystem::exists(path) ? "one that cannot be opened" : "no such file");
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

nlohmann::json parse_json(std::string_view text, const std::string& file) {
    try {
        return nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/true, /*ignore_comments=*/true);
    } catch (const nlohmann::json::parse_error& e) {
        const std::size_t end = std::min<std::size_t>(e.byte, text.size());
        const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(end), '\n'));
        fail_data(kModule, FileLoc{file, line, ""}, "valid JSON", syntax_detail(e.what()));
    } catch (const nlohmann::json::exception& e) {
        fail_data(kModule, FileLoc{file, 0, ""}, "valid JSON", e.what());
    }
}

std::string json_key_path(const std::string& parent, const std::string& key) {
    return parent.empty() ? path_key(key) : parent + "." + path_key(key);
}

std::string JsonReader::child_path(const std::string& key) const { return json_key_path(path_, key); }

void JsonReader::fail(std::string_view expected) const { fail(expected, describe_json(*value_)); }

void JsonReader::fail(std::string_view expected, std::string_view found) const {
    fail_data(kModule, loc(), expected, found);
}

void JsonReader::expect_object() const {
    if (!value_->is_object()) fail("an object");
}

bool JsonReader::has(const std::string& key) {
    expect_object();
    if (std::find(known_.begin(), known_.end(), key) == known_.end()) known_.push_back(key);
    return value_->contains(key);
}

JsonReader JsonReader::at(const std::string& key) {
    if (!has(key)) fail_data(kModule, FileLoc{file_, 0, child_path(key)}, "a value", "no such key");
    return JsonReader(value_->at(key), file_, child_path(key));
}

void JsonReader::comment(const std::string& key) {
    expect_object();
    comments_.push_back(key);
    if (!value_->contains(key)) return;
    const JsonReader text(value_->at(key), file_, child_path(key));
    bool ok = text.is_string();
    if (text.is_array())
        ok = std::all_of(text.raw().begin(), text.raw().end(), [](const nlohmann::json& v) { return v.is_string(); });
    if (!ok) text.fail("a comment (a string or a list of strings)");
}

std::vector<JsonReader> JsonReader::objects(const std::string& key) {
    std::vector<JsonReader> out = at(key).elements();
    for (JsonReader& r : out) r.expect_object();
    return out;
}

double JsonReader::as_number() const {
    if (!value_->is_number() || !std::isfinite(value_->get<double>())) fail("a number");
    return value_->get<double>();
}

double JsonReader::as_number_in(double min, double max) const {
    const std::string expected = fmt::format("a number in [{}, {}]", min, max);
    if (!value_->is_number()) fail(expected);
    const double v = value_->get<double>();
    if (!(v >= min && v <= max)) fail(expected);
    return v;
}

int JsonReader::as_integer() const {
    return as_integer_in(std::numeric_limits<int>::min(), std::numeric_limits<int>::max());
}

int JsonReader::as_integer_in(int min, int max) const {
    const bool bounded = min != std::numeric_limits<int>::min() || max != std::numeric_limits<int>::max();
    const std::string expected = bounded ? fmt::format("an integer in [{}, {}]", min, max) : "an integer";
    if (!value_->is_number_integer()) fail(expected);
    // Compared as double first: get<int> of a huge value would wrap.
    const double v = value_->get<double>();
    if (!(v >= min && v <= max)) fail(expected);
    return static_cast<int>(v);
}

bool JsonReader::as_boolean() const {
    if (!value_->is_boolean()) fail("true or false");
    return value_->get<bool>();
}

std::string JsonReader::as_string() const {
    if (!value_->is_string()) fail("a string");
    return value_->get<std::string>();
}

std::vector<double> JsonReader::as_number_list() const {
    if (!value_->is_array()) fail("an array of numbers");
    std::vector<double> out;
    for (const JsonReader& e : elements()) out.push_back(e.as_number());
    return out;
}

JsonReader JsonReader::as_object() const {
    expect_object();
    return JsonReader(*value_, file_, path_);
}

std::vector<JsonReader> JsonReader::elements() const {
    if (!value_->is_array()) fail("an array");
    std::vector<JsonReader> out;
    out.reserve(value_->size());
    for (std::size_t i = 0; i < value_->size(); ++i)
        out.emplace_back((*value_)[i], file_, fmt::format("{}[{}]", path_, i));
    return out;
}

std::vector<std::pair<std::string, JsonReader>> JsonReader::entries() {
    expect_object();
    std::vector<std::pair<std::string, JsonReader>> out;
    for (auto it = value_->begin(); it != value_->end(); ++it) {
        if (is_comment_key(it.key())) continue;
        known_.push_back(it.key());
        out.emplace_back(it.key(), JsonReader(*it, file_, child_path(it.key())));
    }
    return out;
}

void JsonReader::finish() const {
    if (!value_->is_object()) return;
    for (auto it = value_->begin(); it != value_->end(); ++it) {
        const std::string& key = it.key();
        if (is_comment_key(key) || std::find(comments_.begin(), comments_.end(), key) != comments_.end()) continue;
        if (std::find(known_.begin(), known_.end(), key) != known_.end()) continue;
        std::string keys;
        for (const std::string& k : known_) keys += (keys.empty() ? "" : ", ") + k;
        for (const std::string& k : comments_) keys += (keys.empty() ? "" : ", ") + k;
        fail_data(kModule, FileLoc{file_, 0, child_path(key)},
                  keys.empty() ? std::string("no keys here") : "a known key (" + keys + ")",
                  "\"" + key + "\"");
    }
}

}  // namespace emoface::expression::detail
