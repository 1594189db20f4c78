// The ASCII FAP reader. The format and its tolerances are described in
// fap_io.h; the rule here is that no input, however broken, costs more than
// its own size in memory or time, or ends in anything but InputError.
#include <array>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "emoface/common/error.h"
#include "emoface/common/input_file.h"
#include "emoface/fap/fap_io.h"
#include "text.h"

namespace emoface::fap {

namespace {

using detail::NumberStatus;
using detail::quoted;
using detail::Tokens;

constexpr std::size_t kMaskTokens = kFapCount;            // 68
constexpr std::size_t kGretaMaskTokens = kFapCount + 1;   // 69
// Frame number + 4 viseme + 6 expression + 66 low-level values.
constexpr std::size_t kMaxValueTokens = 1 + 4 + 6 + kLowLevelFapCount;
constexpr double kMinFps = 0.001;
constexpr double kMaxFps = 1e6;

bool is_version(std::string_view token) {
    // digits, optionally '.' digits
    std::size_t i = 0;
    while (i < token.size() && token[i] >= '0' && token[i] <= '9') ++i;
    if (i == 0) return false;
    if (i == token.size()) return true;
    if (token[i] != '.') return false;
    std::size_t j = i + 1;
    while (j < token.size() && token[j] >= '0' && token[j] <= '9') ++j;
    return j > i + 1 && j == token.size();
}

std::string plural(long long n, const char* one, const char* many) {
    return fmt::format("{} {}", n, n == 1 ? one : many);
}

class Reader {
public:
    Reader(std::string_view text, const std::string& source) : lines_(text), source_(source) {}

    FapStream read() {
        std::string_view line;
        long long line_number = 0;
        if (!lines_.next_content(line, line_number))
            error(lines_.line_number(),
                  "expected a header line `version name fps count`, found end of file");

        bool have_pending_mask = false;
        if (looks_like_mask(line)) {
            warn(line_number, fmt::format("no header line `version name fps count`; read as "
                                          "version 2.1 at {} fps",
                                          kHeaderlessFps));
            stream_.fps = kHeaderlessFps;
            have_pending_mask = true;
        } else {
            read_header(line, line_number);
        }

        std::size_t frames_in_file = 0;
        std::size_t trailing_empty = 0;
        long long first_trailing_empty_line = 0;
        while (have_pending_mask || lines_.next_content(line, line_number)) {
            have_pending_mask = false;
            if (frames_in_file == static_cast<std::size_t>(kMaxFapFrames))
                error(line_number, fmt::format("expected at most {} frames, found more", kMaxFapFrames));
            ++frames_in_file;
            FapFrame frame = read_frame(frames_in_file, line, line_number);
            if (frame.mask.none()) {
                if (trailing_empty++ == 0) first_trailing_empty_line = line_number;
            } else {
                trailing_empty = 0;
            }
            stream_.frames.push_back(frame);
        }

        if (declared_count_ >= 0 && static_cast<std::size_t>(declared_count_) != frames_in_file)
            warn(header_line_, fmt::format("the header declares {}, found {}",
                                           plural(declared_count_, "frame", "frames"),
                                           frames_in_file));
        if (trailing_empty > 0) {
            stream_.frames.resize(stream_.frames.size() - trailing_empty);
            warn(first_trailing_empty_line,
                 trailing_empty == 1
                     ? std::string("the last frame transmits no FAP: dropped")
                     : fmt::format("the last {} frames transmit no FAP: dropped", trailing_empty));
        }
        if (suppressed_warnings_ > 0)
            stream_.warnings.push_back(fmt::format("... and {} more {}", suppressed_warnings_,
                                                   suppressed_warnings_ == 1 ? "warning" : "warnings"));
        return std::move(stream_);
    }

private:
    [[noreturn]] void error(long long line, const std::string& what) const {
        throw InputError(fmt::format("fap: {}:{}: {}", source_, line, what));
    }

    void warn(long long line, const std::string& what) {
        // One slot stays free for the "and N more" line.
        if (stream_.warnings.size() + 1 < kMaxWarnings)
            stream_.warnings.push_back(fmt::format("{}:{}: {}", source_, line, what));
        else
            ++suppressed_warnings_;
    }

    static bool looks_like_mask(std::string_view line) {
        Tokens<kGretaMaskTokens> tokens(line);
        if (tokens.count != kMaskTokens && tokens.count != kGretaMaskTokens) return false;
        for (std::size_t i = 0; i < tokens.count; ++i) {
            double v = 0;
            if (detail::parse_number(tokens.items[i], v) != NumberStatus::Ok) return false;
        }
        return true;
    }

    void read_header(std::string_view line, long long line_number) {
        header_line_ = line_number;
        const std::string_view content = detail::trim(line);
        // First token, last token, the one before it; the name is what lies
        // between (a Windows path, spaces and all).
        const auto token_end = [&](std::size_t from) {
            while (from < content.size() && !detail::is_space(content[from])) ++from;
            return from;
        };
        const auto token_start = [&](std::size_t end) {  // of the token ending at end
            while (end > 0 && !detail::is_space(content[end - 1])) --end;
            return end;
        };
        const auto skip_space_back = [&](std::size_t end) {
            while (end > 0 && detail::is_space(content[end - 1])) --end;
            return end;
        };
        const std::size_t version_end = token_end(0);
        const std::size_t count_start = token_start(content.size());
        const std::size_t fps_end = skip_space_back(count_start);
        const std::size_t fps_start = token_start(fps_end);
        if (count_start <= version_end || fps_start <= version_end)
            error(line_number, fmt::format("expected a header `version name fps count`, found {}",
                                           quoted(content)));
        const std::string_view version = content.substr(0, version_end);
        const std::string_view fps_token = content.substr(fps_start, fps_end - fps_start);
        const std::string_view count_token = content.substr(count_start);
        if (!is_version(version))
            error(line_number, fmt::format("expected a header `version name fps count`, found {}",
                                           quoted(content)));

        double fps = 0;
        if (detail::parse_number(fps_token, fps) != NumberStatus::Ok || !(fps >= kMinFps && fps <= kMaxFps))
            error(line_number,
                  fmt::format("expected a frame rate from {} to {} as the header's "
                              "second-to-last field, found {}",
                              kMinFps, kMaxFps, quoted(fps_token)));
        long long count = 0;
        if (!detail::parse_integer(count_token, count) || count < 0)
            error(line_number, fmt::format("expected a frame count (an integer >= 0) as the "
                                           "header's last field, found {}",
                                           quoted(count_token)));
        if (count > kMaxFapFrames)
            error(line_number,
                  fmt::format("expected a frame count of at most {}, found {}", kMaxFapFrames, count));

        stream_.version = std::string(version);
        stream_.name = std::string(detail::trim(content.substr(version_end, fps_start - version_end)));
        stream_.fps = fps;
        declared_count_ = count;
        if (version != "2.0" && version != "2.1")
            warn(line_number, fmt::format("version {} is not 2.0 or 2.1; read as 2.1", version));
    }

    int read_int_field(std::string_view token, std::size_t ordinal, const char* field,
                       long long line_number) const {
        double v = 0;
        if (detail::parse_number(token, v) != NumberStatus::Ok || v != std::floor(v) ||
            v < INT_MIN || v > INT_MAX)
            error(line_number, fmt::format("frame {}: expected an integer for {}, found {}",
                                           ordinal, field, quoted(token)));
        return static_cast<int>(v);
    }

    void check_code(int value, int limit, std::size_t ordinal, const char* field, long long line_number) {
        if (value < 0 || value > limit)
            warn(line_number, fmt::format("frame {}: {} {} is outside 0..{}", ordinal, field, value, limit));
    }

    FapFrame read_frame(std::size_t ordinal, std::string_view mask_line, long long mask_line_number) {
        FapFrame frame;
        Tokens<kGretaMaskTokens> mask(mask_line);
        if (mask.count != kMaskTokens && mask.count != kGretaMaskTokens)
            error(mask_line_number,
                  fmt::format("frame {}: expected a mask of {} tokens ({} from Greta's Java "
                              "writer), found {}",
                              ordinal, kMaskTokens, kGretaMaskTokens, mask.count));
        for (std::size_t i = 0; i < kMaskTokens; ++i) {
            double v = 0;
            if (detail::parse_number(mask.items[i], v) != NumberStatus::Ok)
                error(mask_line_number, fmt::format("frame {}: expected a mask token (0 or 1) for "
                                                    "FAP {}, found {}",
                                                    ordinal, i + 1, quoted(mask.items[i])));
            if (v != 0) frame.mask.set(i);
        }
        if (mask.count == kGretaMaskTokens && !warned_69_) {
            warned_69_ = true;
            warn(mask_line_number, "mask lines have 69 tokens (Greta's Java writer): the 69th is ignored");
        }

        std::string_view line;
        long long line_number = 0;
        if (!lines_.next_content(line, line_number))
            error(mask_line_number, fmt::format("frame {}: expected a values line after this mask "
                                                "line, found end of file",
                                                ordinal));
        Tokens<kMaxValueTokens> values(line);

        std::bitset<kFapCount> low_level = frame.mask;
        low_level.reset(0).reset(1);
        const std::size_t low = low_level.count();
        const bool viseme = frame.mask[0], expression = frame.mask[1];
        // FAP 1 takes 1 or 4 values, FAP 2 1 or 6: 1+1, 4+1, 1+6 and 4+6 all
        // differ, so the count says which forms the line uses.
        const std::array<std::size_t, 2> viseme_forms = viseme ? std::array<std::size_t, 2>{1, 4}
                                                               : std::array<std::size_t, 2>{0, 0};
        const std::array<std::size_t, 2> expression_forms =
            expression ? std::array<std::size_t, 2>{1, 6} : std::array<std::size_t, 2>{0, 0};
        std::size_t viseme_values = 0, expression_values = 0;
        bool matched = false;
        for (std::size_t v : viseme_forms)
            for (std::size_t e : expression_forms)
                if (1 + v + e + low == values.count) {
                    viseme_values = v;
                    expression_values = e;
                    matched = true;
                }
        if (!matched) error(line_number, count_message(ordinal, viseme, expression, low, values.count));

        long long number = 0;
        if (!detail::parse_integer(values.items[0], number) || number < 0)
            error(line_number, fmt::format("frame {}: expected a frame number (an integer >= 0), "
                                           "found {}",
                                           ordinal, quoted(values.items[0])));
        frame.number = number;
        if (have_previous_number_ && number <= previous_number_ && !warned_order_) {
            warned_order_ = true;
            warn(line_number, fmt::format("frame {}: frame number {} does not follow {}; timing "
                                          "follows the order in the file",
                                          ordinal, number, previous_number_));
        }
        have_previous_number_ = true;
        previous_number_ = number;

        std::size_t next = 1;
        const auto field = [&](const char* name) {
            return read_int_field(values.items[next++], ordinal, name, line_number);
        };
        if (viseme_values == 4) {
            frame.viseme.select1 = field("viseme_select1");
            frame.viseme.select2 = field("viseme_select2");
            frame.viseme.blend = field("viseme_blend");
            frame.viseme.def = field("viseme_def");
        } else if (viseme_values == 1) {
            frame.viseme.select1 = field("viseme_select1");
        }
        if (viseme) {
            check_code(frame.viseme.select1, kVisemeCodeCount - 1, ordinal, "viseme_select1", line_number);
            check_code(frame.viseme.select2, kVisemeCodeCount - 1, ordinal, "viseme_select2", line_number);
            check_code(frame.viseme.blend, kMaxIntensity, ordinal, "viseme_blend", line_number);
        }
        if (expression_values == 6) {
            frame.expression.select1 = field("expression_select1");
            frame.expression.intensity1 = field("expression_intensity1");
            frame.expression.select2 = field("expression_select2");
            frame.expression.intensity2 = field("expression_intensity2");
            frame.expression.init_face = field("init_face");
            frame.expression.def = field("expression_def");
        } else if (expression_values == 1) {
            frame.expression.select1 = field("expression_select1");
        }
        if (expression) {
            const Expression& e = frame.expression;
            check_code(e.select1, kExpressionCodeCount - 1, ordinal, "expression_select1", line_number);
            check_code(e.intensity1, kMaxIntensity, ordinal, "expression_intensity1", line_number);
            check_code(e.select2, kExpressionCodeCount - 1, ordinal, "expression_select2", line_number);
            check_code(e.intensity2, kMaxIntensity, ordinal, "expression_intensity2", line_number);
        }
        for (std::size_t i = 2; i < kFapCount; ++i) {
            if (!frame.mask[i]) continue;
            const std::string_view token = values.items[next++];
            double v = 0;
            switch (detail::parse_number(token, v)) {
                case NumberStatus::Ok: frame.values[i] = v; break;
                case NumberStatus::NotANumber:
                    error(line_number, fmt::format("frame {}: expected a number for FAP {} {}, "
                                                   "found {}",
                                                   ordinal, i + 1, fap_table()[i].name, quoted(token)));
                case NumberStatus::NotFinite:
                    error(line_number, fmt::format("frame {}: expected a finite number for FAP {} "
                                                   "{}, found {}",
                                                   ordinal, i + 1, fap_table()[i].name, quoted(token)));
            }
        }
        return frame;
    }

    static std::string count_message(std::size_t ordinal, bool viseme, bool expression,
                                     std::size_t low, std::size_t found) {
        const std::size_t base = 1 + low;
        std::string counts, parts = "the frame number";
        if (viseme && expression) {
            counts = fmt::format("{}, {}, {} or {}", base + 2, base + 5, base + 7, base + 10);
            parts += ", FAP 1 as 1 or 4 values, FAP 2 as 1 or 6 values";
        } else if (viseme) {
            counts = fmt::format("{} or {}", base + 1, base + 4);
            parts += ", FAP 1 as 1 or 4 values";
        } else if (expression) {
            counts = fmt::format("{} or {}", base + 1, base + 6);
            parts += ", FAP 2 as 1 or 6 values";
        } else {
            counts = fmt::format("{}", base);
        }
        parts += fmt::format(" and {} for the low-level FAPs the mask sets",
                             plural(static_cast<long long>(low), "value", "values"));
        return fmt::format("frame {}: expected {} tokens ({}), found {}", ordinal, counts, parts, found);
    }

    detail::LineReader lines_;
    const std::string& source_;
    FapStream stream_;
    long long header_line_ = 0;
    long long declared_count_ = -1;  // -1: no header
    std::size_t suppressed_warnings_ = 0;
    bool warned_69_ = false;
    bool warned_order_ = false;
    bool have_previous_number_ = false;
    long long previous_number_ = 0;
};

}  // namespace

FapStream parse_fap(std::string_view text, const std::string& source_name) {
    // Windows editors may start a text file with a UTF-8 byte order mark.
    constexpr std::string_view kBom = "\xEF\xBB\xBF";
    if (text.substr(0, kBom.size()) == kBom) text.remove_prefix(kBom.size());
    return Reader(text, source_name).read();
}

FapStream read_fap_file(const std::string& path) {
    return parse_fap(read_input_file(path, static_cast<std::uint64_t>(kMaxFapFileBytes), "fap"), path);
}

}  // namespace emoface::fap
