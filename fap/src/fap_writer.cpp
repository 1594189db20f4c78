// The ASCII FAP writer: writes exactly what fap_reader.cpp reads back.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <string>

#include "emoface/common/atomic_file.h"
#include "emoface/common/error.h"
#include "emoface/fap/fap_io.h"
#include "text.h"

namespace emoface::fap {

namespace {

bool is_version(std::string_view v) {
    std::size_t i = 0;
    while (i < v.size() && v[i] >= '0' && v[i] <= '9') ++i;
    if (i == 0) return false;
    if (i == v.size()) return true;
    if (v[i] != '.' || i + 1 == v.size()) return false;
    for (std::size_t j = i + 1; j < v.size(); ++j)
        if (v[j] < '0' || v[j] > '9') return false;
    return true;
}

std::string header_line(const FapStream& s) {
    if (!is_version(s.version))
        fail<InputError>("fap: format_fap: expected a version such as 2.1, found {}",
                         detail::quoted(s.version));
    if (s.name.find_first_of("\r\n") != std::string::npos || detail::trim(s.name) != s.name)
        fail<InputError>("fap: format_fap: expected a name without line breaks or leading and "
                         "trailing spaces, found {}",
                         detail::quoted(s.name));
    if (!(std::isfinite(s.fps) && s.fps >= 0.001 && s.fps <= 1e6))
        fail<InputError>("fap: format_fap: expected a frame rate from 0.001 to 1000000, found {}", s.fps);
    if (static_cast<long long>(s.frames.size()) > kMaxFapFrames)
        fail<InputError>("fap: format_fap: expected at most {} frames, found {}", kMaxFapFrames,
                         s.frames.size());
    std::string line = s.version;
    if (!s.name.empty()) line += " " + s.name;
    line += fmt::format(" {} {}", s.fps, s.frames.size());
    // A name of 65 or 66 numbers would make the header read as a mask line.
    detail::Tokens<kFapCount + 1> tokens(line);
    if (tokens.count == kFapCount || tokens.count == kFapCount + 1) {
        bool numeric = true;
        for (std::size_t i = 0; i < tokens.count && numeric; ++i) {
            double v = 0;
            numeric = detail::parse_number(tokens.items[i], v) == detail::NumberStatus::Ok;
        }
        if (numeric)
            fail<InputError>("fap: format_fap: expected a name that is not {} numbers (the header "
                             "would read as a mask line), found {}",
                             tokens.count - 3, detail::quoted(s.name));
    }
    return line;
}

}  // namespace

std::string format_fap(const FapStream& s) {
    std::string out = header_line(s);
    out += '\n';
    fmt::memory_buffer line;
    for (std::size_t k = 0; k < s.frames.size(); ++k) {
        const FapFrame& f = s.frames[k];
        if (f.number < 0)
            fail<InputError>("fap: format_fap: frame {}: expected a frame number >= 0, found {}",
                             k + 1, f.number);
        for (std::size_t i = 0; i < kFapCount; ++i) {
            out += f.mask[i] ? '1' : '0';
            out += i + 1 < kFapCount ? ' ' : '\n';
        }
        line.clear();
        fmt::format_to(std::back_inserter(line), "{}", f.number);
        if (f.mask[0]) {
            const Viseme& v = f.viseme;
            fmt::format_to(std::back_inserter(line), " {} {} {} {}", v.select1, v.select2, v.blend, v.def);
        }
        if (f.mask[1]) {
            const Expression& e = f.expression;
            fmt::format_to(std::back_inserter(line), " {} {} {} {} {} {}", e.select1, e.intensity1,
                           e.select2, e.intensity2, e.init_face, e.def);
        }
        for (std::size_t i = 2; i < kFapCount; ++i) {
            if (!f.mask[i]) continue;
            if (!std::isfinite(f.values[i]))
                fail<InputError>("fap: format_fap: frame {}: expected a finite value for FAP {} {}, "
                                 "found {}",
                                 k + 1, i + 1, fap_table()[i].name, f.values[i]);
            // The shortest text that reads back as the same double.
            fmt::format_to(std::back_inserter(line), " {}", f.values[i]);
        }
        out.append(line.data(), line.size());
        out += '\n';
    }
    return out;
}

void write_fap_file(const FapStream& stream, const std::string& path) {
    const std::string text = format_fap(stream);
    write_file_atomically(path, text, "fap");
}

namespace {

constexpr std::size_t kXfaceNameBytes = 254;  // FAPFile::open reads the name into char[255]
constexpr double kXfaceMaxFps = 32767;        // its frame rate is a short
constexpr double kXfaceMaxValue = 2147483647;  // an int, as its viseme and expression fields are read

std::string xface_name(const std::string& name) {
    std::string out;
    for (char c : name) {
        if (std::isspace(static_cast<unsigned char>(c))) {
            if (!out.empty() && out.back() != '_') out += '_';
        } else {
            out += c;
        }
    }
    while (!out.empty() && out.back() == '_') out.pop_back();
    if (out.empty()) out = "emoface";
    if (out.size() > kXfaceNameBytes) {
        out.resize(kXfaceNameBytes);
        // Not in the middle of a UTF-8 sequence.
        while (!out.empty() && (static_cast<unsigned char>(out.back()) & 0xC0) == 0x80) out.pop_back();
        if (!out.empty() && (static_cast<unsigned char>(out.back()) & 0x80)) out.pop_back();
    }
    return out;
}

// Resolved frames at `fps`, as FapStream::sample interpolates them (the
// viseme and expression of the earlier frame).
std::vector<FapFrame> resample_resolved(const std::vector<FapFrame>& frames, double from_fps, double fps) {
    const double duration = static_cast<double>(frames.size()) / from_fps;
    const auto count = static_cast<std::size_t>(std::max(1.0, std::round(duration * fps)));
    std::vector<FapFrame> out(count);
    for (std::size_t k = 0; k < count; ++k) {
        const double position = static_cast<double>(k) / fps * from_fps;
        const std::size_t a = std::min(static_cast<std::size_t>(position), frames.size() - 1);
        const std::size_t b = std::min(a + 1, frames.size() - 1);
        const double t = std::clamp(position - static_cast<double>(a), 0.0, 1.0);
        FapFrame f = frames[a];
        for (std::size_t i = 2; i < kFapCount; ++i)
            if (frames[b].mask[i]) f.values[i] += (frames[b].values[i] - f.values[i]) * t;
        std::bitset<kFapCount> low_level = frames[b].mask;
        f.mask |= low_level.reset(0).reset(1);
        out[k] = f;
    }
    return out;
}

}  // namespace

FapStream for_xface(const FapStream& stream) {
    if (stream.frames.empty()) fail<InputError>("fap: for_xface: expected at least one frame, found none");
    if (!(std::isfinite(stream.fps) && stream.fps > 0))
        fail<InputError>("fap: for_xface: expected a positive frame rate, found {}", stream.fps);
    FapStream out;
    out.version = stream.version;
    out.name = xface_name(stream.name);
    out.warnings = stream.warnings;
    out.fps = std::clamp(std::round(stream.fps), 1.0, kXfaceMaxFps);
    out.frames = resolve_untransmitted(stream).frames;
    if (out.fps != stream.fps) out.frames = resample_resolved(out.frames, stream.fps, out.fps);
    for (std::size_t k = 0; k < out.frames.size(); ++k) {
        FapFrame& f = out.frames[k];
        f.number = static_cast<long long>(k);
        for (std::size_t i = 2; i < kFapCount; ++i) {
            // -0 would read back as 0 but print as "-0".
            f.values[i] = f.mask[i] ? std::round(f.values[i]) + 0.0 : 0.0;
            // Past this the writer's shortest form has an exponent, and no
            // face moves that far.
            if (!(std::abs(f.values[i]) <= kXfaceMaxValue))
                fail<InputError>("fap: for_xface: frame {}: expected FAP {} {} within +-{:g}, found {}", k, i + 1,
                                 fap_table()[i].name, kXfaceMaxValue, f.values[i]);
        }
    }
    return out;
}

bool same_content(const FapStream& a, const FapStream& b) {
    return a.version == b.version && a.name == b.name && a.fps == b.fps && a.frames == b.frames;
}

}  // namespace emoface::fap
