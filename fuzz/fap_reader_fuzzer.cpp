// libFuzzer target for the FAP reader. Any input may fail with
// emoface::Error, nothing else: no crash, no other exception, no sanitizer
// report. What the reader accepts must also survive the writer and read back
// as the same stream, and sampling it must stay in bounds.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "emoface/common/error.h"
#include "emoface/fap/fap_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace emoface::fap;
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    FapStream stream;
    try {
        stream = parse_fap(text, "fuzz.fap");
    } catch (const emoface::Error&) {
        return 0;
    }
    // Round trip: the writer takes every stream the reader produces.
    const FapStream again = parse_fap(format_fap(stream), "again.fap");
    if (!same_content(stream, again)) std::abort();
    if (stream.warnings.size() > kMaxWarnings) std::abort();
    // Sampling in and around the stream.
    const double d = stream.duration();
    for (double t : {-1.0, 0.0, d * 0.37, d * 0.5, d, d + 1})
        (void)stream.sample(t);
    return 0;
}
