#pragma once
// A JSON object of FAP values, {"fap name or number": value, ...}, as read by
// every data file that holds FAP vectors (action units, visemes).
#include <algorithm>

#include "emoface/expression/fap_values.h"
#include "json_reader.h"

namespace emoface::expression::detail {

// `allowed(number)` says which FAPs may appear; `allowed_text` names them
// for the message.
template <typename Allowed>
FapValues read_fap_values(JsonReader faps, Allowed allowed, const char* allowed_text) {
    FapValues out{};
    for (const auto& [key, value] : faps.as_object().entries()) {
        int number = 0;
        if (auto f = fap::find_fap(key)) {
            number = *f;
        } else if (!key.empty() && key.size() <= 3 &&
                   std::all_of(key.begin(), key.end(), [](char c) { return c >= '0' && c <= '9'; })) {
            number = std::stoi(key);
        } else {
            value.fail("a FAP name or number as the key", "\"" + key + "\"");
        }
        if (!allowed(number))
            value.fail(allowed_text, fmt::format("FAP {} ({})", number,
                                                 number >= 1 && number <= fap::kFapCount
                                                     ? std::string(fap::fap_info(number).name)
                                                     : "?"));
        const double v = value.as_number();
        if (out[number - 1] != 0.0) value.fail("each FAP once", fmt::format("FAP {} a second time", number));
        out[number - 1] = v;
    }
    return out;
}

}  // namespace emoface::expression::detail
