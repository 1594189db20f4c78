#include "json_reader.h"

#include <algorithm>
#include <cfloat>
#include <limits>

#include "emoface/common/input_file.h"

namespace emoface::expression::detail {
namespace {

constexpr const char* kModule = "expression";

bool is_comment_key(const std::string& key) { return !key.empty() && key[0] == '_'; }

// The text after "line L, column C: " in nlohmann's parse message.
std::string syntax_detail(const std::string& what) {
    const auto column = what.find("column ");
    const auto colon = column == std::string::npos ? std::string::npos : what.find(": ", column);
    return colon == std::string::npos ? what : what.substr(colon + 2);
}

// Keys and values are the file's text: shown cut and with control
// characters escaped, so a message stays one short line.
constexpr std::size_t kMaxShownKey = 24;
constexpr int kMaxDepth = 256;  // nesting of arrays and objects; data files use < 10

// A key as it appears in a path: plain when it is a name or a number, quoted
// when it holds dots or other marks ("feature_points."2.1".vertex").
std::string path_key(const std::string& key) {
    const bool plain = !key.empty() && key.size() <= kMaxShownKey &&
                       std::all_of(key.begin(), key.end(), [](char c) {
                           return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                                  c == '_' || c == '-';
                       });
    return plain ? key : "\"" + echo_input(key, kMaxShownKey) + "\"";
}

// nlohmann's DOM builder, told where in the document it is, so that an error
// the parser finds (a syntax error, a number beyond double range) names the
// key path as well as the line, and nesting is bounded.
class LocatingParser : public nlohmann::detail::json_sax_dom_parser<nlohmann::json> {
    using Base = nlohmann::detail::json_sax_dom_parser<nlohmann::json>;

public:
    LocatingParser(nlohmann::json& root, std::string_view text, const std::string& file)
        : Base(root, true), text_(text), file_(file) {}

    bool null() { return value(), Base::null(); }
    bool boolean(bool v) { return value(), Base::boolean(v); }
    bool number_integer(number_integer_t v) { return value(), Base::number_integer(v); }
    bool number_unsigned(number_unsigned_t v) { return value(), Base::number_unsigned(v); }
    bool number_float(number_float_t v, const string_t& s) { return value(), Base::number_float(v, s); }
    bool string(string_t& v) { return value(), Base::string(v); }
    bool binary(binary_t& v) { return value(), Base::binary(v); }
    bool start_object(std::size_t n) { return open(false), Base::start_object(n); }
    bool end_object() { return frames_.pop_back(), Base::end_object(); }
    bool start_array(std::size_t n) { return open(true), Base::start_array(n); }
    bool end_array() { return frames_.pop_back(), Base::end_array(); }
    bool key(string_t& k) {
        frames_.back().key = k;
        return Base::key(k);
    }

    template <class Exception>
    bool parse_error(std::size_t byte, const std::string& token, const Exception& e) {
        const FileLoc at{file_, line_at(byte), path()};
        if (e.id == 406)  // number overflow
            fail_data(kModule, at, "a number", echo_input(token, 40) + ", beyond the range of a double");
        fail_data(kModule, at, "valid JSON", echo_input(syntax_detail(e.what()), 160));
    }

private:
    struct Frame {
        bool array = false;
        std::size_t count = 0;  // elements started, in an array
        std::string key;        // the last key read, in an object
    };

    int line_at(std::size_t byte) const {
        const std::size_t end = std::min(byte, text_.size());
        return 1 + static_cast<int>(std::count(text_.begin(), text_.begin() + static_cast<long>(end), '\n'));
    }
    // The value being read: the innermost array's next element, or the
    // element an outer array is inside.
    std::string path() const {
        std::string out;
        for (std::size_t i = 0; i < frames_.size(); ++i) {
            const Frame& f = frames_[i];
            const bool innermost = i + 1 == frames_.size();
            if (f.array) out += fmt::format("[{}]", innermost ? f.count : f.count - 1);
            else if (!f.key.empty() || !innermost) out = json_key_path(out, f.key);
        }
        return out;
    }
    void value() {
        if (!frames_.empty() && frames_.back().array) ++frames_.back().count;
    }
    void open(bool array) {
        value();
        if (static_cast<int>(frames_.size()) >= kMaxDepth)
            fail_data(kModule, FileLoc{file_, 0, ""}, fmt::format("at most {} levels of nesting", kMaxDepth),
                      "more");
        frames_.push_back({array, 0, {}});
    }

    std::string_view text_;
    const std::string& file_;
    std::vector<Frame> frames_;
};


}  // namespace

std::string describe_json(const nlohmann::json& value) {
    constexpr std::size_t kMax = 40;
    // Containers dumped whole only to be cut would cost their size; strings
    // are escaped by dump() itself.
    std::string text;
    if (value.is_string()) text = nlohmann::json(value.get_ref<const std::string&>().substr(0, 4 * kMax)).dump();
    else if (value.is_array() && value.size() > kMax) text = "an array of " + std::to_string(value.size()) + " values";
    else if (value.is_object() && value.size() > kMax) text = "an object of " + std::to_string(value.size()) + " keys";
    else text = value.dump();
    if (text.size() > kMax) text = echo_input(text, kMax);
    return text;
}

std::string read_text_file(const std::string& path) { return read_input_file(path, kMaxJsonFileBytes, kModule); }

nlohmann::json parse_json(std::string_view text, const std::string& file) {
    nlohmann::json doc;
    LocatingParser parser(doc, text, file);
    try {
        nlohmann::json::sax_parse(text, &parser, nlohmann::json::input_format_t::json, /*strict=*/true,
                                  /*ignore_comments=*/true);
    } catch (const nlohmann::json::exception& e) {
        fail_data(kModule, FileLoc{file, 0, ""}, "valid JSON", echo_input(e.what(), 160));
    }
    return doc;
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
    // Stored as float in many places (mesh points, textures, GL uniforms):
    // what float cannot hold would become inf there.
    const double v = value_->get<double>();
    if (std::abs(v) > FLT_MAX) fail("a number within the range of a float (3.4e38)");
    return v;
}

double JsonReader::as_number_in(double min, double max) const {
    const std::string expected = fmt::format("a number in [{}, {}]", min, max);
    if (!value_->is_number()) fail(expected);
    const double v = value_->get<double>();
    if (!(v >= min && v <= max)) fail(expected);
    if (std::abs(v) > FLT_MAX) fail("a number within the range of a float (3.4e38)");
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
                  "\"" + echo_input(key, kMaxShownKey) + "\"");
    }
}

}  // namespace emoface::expression::detail
