#pragma once
// Builders for FAP file text in tests.
#include <initializer_list>
#include <string>

namespace emoface::fap::test {

// A mask line of `width` tokens with 1 at the given FAP numbers.
inline std::string mask_line(std::initializer_list<int> faps, int width = 68) {
    std::string out;
    for (int i = 1; i <= width; ++i) {
        bool set = false;
        for (int f : faps) set = set || f == i;
        if (i > 1) out += ' ';
        out += set ? '1' : '0';
    }
    return out;
}

}  // namespace emoface::fap::test
