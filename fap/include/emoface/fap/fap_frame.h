#pragma once
// One frame of MPEG-4 facial animation: the 66 low-level FAP values with the
// mask of those the frame transmits, and the two high-level FAPs as structs.
#include <array>
#include <bitset>
#include <string_view>

#include "emoface/fap/fap_table.h"

namespace emoface::fap {

// FAP 1. Codes: 0 none, 1 p b m, 2 f v, 3 T D, 4 t d, 5 k g, 6 tS dZ S,
// 7 s z, 8 n l, 9 r, 10 A:, 11 e, 12 I, 13 Q, 14 U. blend 0..63 weighs
// select1 against select2.
struct Viseme {
    int select1 = 0, select2 = 0, blend = 0, def = 0;
};

// FAP 2. Codes: 0 neutral, 1 joy, 2 sadness, 3 anger, 4 fear, 5 disgust,
// 6 surprise; intensities 0..63.
struct Expression {
    int select1 = 0, intensity1 = 0, select2 = 0, intensity2 = 0, init_face = 0, def = 0;
};

inline constexpr int kVisemeCodeCount = 15;     // 0..14
inline constexpr int kExpressionCodeCount = 7;  // 0..6
inline constexpr int kMaxIntensity = 63;

// "neutral", "joy", "sadness", "anger", "fear", "disgust", "surprise"; "" for
// another code.
std::string_view expression_name(int code);
// "none", "p b m", "f v", ... "U" (the codes above); "" for another code.
std::string_view viseme_name(int code);

bool operator==(const Viseme& a, const Viseme& b);
bool operator!=(const Viseme& a, const Viseme& b);
bool operator==(const Expression& a, const Expression& b);
bool operator!=(const Expression& a, const Expression& b);

struct FapFrame {
    // The number the file gives this frame. Files number from 0, from 1, with
    // gaps, or with millisecond timestamps: it is kept for reference and
    // written back, but timing follows a frame's position in its stream.
    long long number = 0;
    // Index fap - 1. values[0] and values[1] stay 0: FAP 1 and 2 live in
    // `viseme` and `expression`. A value the mask does not transmit means
    // nothing by itself (see fap_stream.h for how it is resolved).
    std::array<double, kFapCount> values{};
    std::bitset<kFapCount> mask;  // bit fap - 1: the frame transmits FAP fap
    Viseme viseme;                // meaningful when mask[0]
    Expression expression;        // meaningful when mask[1]

    // fap is 1..68; anything else throws emoface::Error.
    bool has(int fap) const;
    double get(int fap) const;
    // Sets a low-level FAP (3..68) and marks it transmitted; FAP 1 and 2 have
    // set_viseme / set_expression.
    void set(int fap, double value);
    void set_viseme(const Viseme& v);
    void set_expression(const Expression& e);
    // Stops transmitting fap (1..68) and zeroes what it held.
    void clear(int fap);
    // Number of FAPs transmitted (FAP 1 and 2 count one each).
    int transmitted_count() const { return static_cast<int>(mask.count()); }
};

// Same transmitted content: number, mask, the values the mask transmits, the
// viseme when FAP 1 is transmitted and the expression when FAP 2 is. Values
// the mask does not transmit are not compared (the writer does not write them).
bool operator==(const FapFrame& a, const FapFrame& b);
bool operator!=(const FapFrame& a, const FapFrame& b);

}  // namespace emoface::fap
