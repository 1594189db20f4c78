// What `play` and `view` change to keep up without a GPU (issue 13), held to
// the pictures they replace: the fast wrinkle morph they take by default
// draws a face within the golden tolerance (tests/render/golden.h) of the
// exact morph's, and only the commands that play in time take it.
#include <string>

#include <gtest/gtest.h>

#include "../render/golden.h"
#include "emoface/common/error.h"
#include "emoface/expression/emotion.h"
#include "emoface/render/image_diff.h"
#include "session.h"

namespace {

using namespace emoface;
using emoface::apps::Session;
using emoface::apps::SessionArgs;
using emoface::apps::SessionOptions;

// The golden suite's face (half mesh resolution, 512 maps and texture, 512²
// with 4x MSAA, CPU morph), so its tolerance means the same thing here.
SessionOptions golden_like(morph::Accuracy accuracy) {
    SessionOptions o;
    o.backend = morph::Backend::Cpu;
    o.face_resolution = 0.5;
    o.texture_size = 512;
    o.wrinkle_size = 512;
    o.width = o.height = 512;
    o.samples = 4;
    o.morph_accuracy = accuracy;
    return o;
}

// Mixes whose wrinkles cover the brow, the eyes and the mouth: the fast
// morph's interpolated cells fall where the lines bend the map most.
const char* const kMixes[] = {"joy", "surprise", "0.7 anger + 0.3 fear"};

TEST(Realtime, FastMorphDrawsTheFaceWithinTheGoldenToleranceOfTheExactOne) {
    Session exact(golden_like(morph::Accuracy::Exact));
    Session fast(golden_like(morph::Accuracy::Fast));
    for (const char* mix : kMixes) {
        SCOPED_TRACE(mix);
        const expression::EmotionMix m = expression::parse_emotion_mix(mix);
        const render::ImageRGBA8 a = render::testing::downsample2x(exact.render_frame(exact.face_state(m)));
        const render::ImageRGBA8 b = render::testing::downsample2x(fast.render_frame(fast.face_state(m)));
        const render::ImageDiff d = render::diff_images(b, a);
        const auto& tol = render::testing::kFaceTolerance;
        EXPECT_LE(d.max_channel_diff, tol.max_channel_diff);
        EXPECT_LE(d.mean_diff, tol.mean_diff);
        // Not vacuous: the wrinkle maps themselves differ (the fast morph
        // interpolates), and that difference reaches the picture.
        EXPECT_NE(exact.wrinkle_map().pixels, fast.wrinkle_map().pixels);
        std::printf("%s: fast morph against exact: max channel difference %d, mean %.4f, PSNR %.1f dB\n", mix,
                    d.max_channel_diff, d.mean_diff, d.psnr());
    }
}

TEST(Realtime, OnlyTheCommandsThatPlayInTimeTakeTheFastMorph) {
    struct Case {
        const char* command;
        std::string flag;
        morph::Accuracy expected;
    };
    const Case cases[] = {
        {"play", "", morph::Accuracy::Fast},      {"view", "", morph::Accuracy::Fast},
        {"mix", "", morph::Accuracy::Exact},      {"inspect", "", morph::Accuracy::Exact},
        {"morph", "", morph::Accuracy::Exact},    {"play", "exact", morph::Accuracy::Exact},
        {"mix", "fast", morph::Accuracy::Fast},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(std::string(c.command) + " --morph-accuracy '" + c.flag + "'");
        SessionArgs args;
        args.morph_accuracy = c.flag;
        EXPECT_EQ(args.resolve(c.command, 64, 64).morph_accuracy, c.expected);
    }
}

TEST(Realtime, AnUnknownMorphAccuracyIsRefusedWithTheChoices) {
    SessionArgs args;
    args.morph_accuracy = "quick";
    try {
        args.resolve("play", 64, 64);
        FAIL() << "expected an InputError";
    } catch (const InputError& e) {
        EXPECT_STREQ(e.what(), "play: --morph-accuracy 'quick': expected exact or fast");
    }
}

}  // namespace
