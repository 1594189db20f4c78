// libFuzzer target for the capture readers (OpenFace, Live Link Face and
// MediaPipe CSVs; expression/capture.h). Any input may fail with
// emoface::Error, nothing else: no crash, no other exception, no sanitizer
// report. A stream the readers make must survive the FAP writer and read
// back as the same stream, and must not outgrow its file by more than the
// row-gap limit allows.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "emoface/common/error.h"
#include "emoface/expression/capture.h"
#include "emoface/fap/fap_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const emoface::expression::CaptureTables tables =
        emoface::expression::load_capture_tables(EMOFACE_DATA_DIR);
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    emoface::fap::FapStream stream;
    try {
        stream = emoface::expression::parse_capture_csv(text, "fuzz.csv", tables);
    } catch (const emoface::Error&) {
        return 0;
    }
    if (stream.frames.empty() || stream.frames.size() > 100 * size + 1) std::abort();
    const auto again = emoface::fap::parse_fap(emoface::fap::format_fap(stream), "again.fap");
    if (!emoface::fap::same_content(stream, again)) std::abort();
    return 0;
}
