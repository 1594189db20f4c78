// libFuzzer target for a user's face: an OBJ mesh and its FDP JSON, split at
// the first "\n%%\n" of the input (no separator: all OBJ, an empty FDP). Any
// input may fail with emoface::InputError, nothing else: no crash, no other
// exception (an nlohmann-json or OpenMesh one leaking out), no sanitizer
// report, and the message is one line of bounded length. A face that loads
// is one the rig was built on (the loader checks), with finite FAPU.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "emoface/common/error.h"
#include "emoface/expression/face_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view input(reinterpret_cast<const char*>(data), size);
    const std::size_t cut = input.find("\n%%\n");
    const std::string_view obj = input.substr(0, cut);
    const std::string_view fdp = cut == std::string_view::npos ? std::string_view() : input.substr(cut + 4);
    try {
        const emoface::expression::Face face =
            emoface::expression::parse_obj_with_fdp(obj, "fuzz.obj", fdp, "fuzz.fdp.json");
        const auto& u = face.fapu;
        for (double v : {u.es, u.ens, u.mns, u.mw, u.irisd})
            if (!(std::isfinite(v) && v > 0)) std::abort();
    } catch (const emoface::InputError& e) {
        const std::string line = emoface::error_line(e);
        if (line.size() > emoface::kMaxErrorLine || line.find('\n') != std::string::npos) std::abort();
    }
    return 0;
}
