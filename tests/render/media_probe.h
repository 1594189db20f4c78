#pragma once
// Tests read the videos they make back through libavformat and libavcodec,
// as a player would (never the writer's own bookkeeping): the streams and
// their codecs, every packet's time, and the sound decoded to samples. Also
// the sine or click WAV files tests use as sound (written here: no third-party
// data). Header-only: tests/render and tests/apps include it.
extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/channel_layout.h>
#include <libavutil/log.h>
#include <libavutil/samplefmt.h>
}

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace emoface::testing {

struct MediaStream {
    std::string codec;  // "h264", "aac", "vp9", "opus", "mjpeg", "pcm_s16le"
    AVMediaType type = AVMEDIA_TYPE_UNKNOWN;
    AVRational time_base{0, 1};
    std::vector<std::int64_t> pts;  // every packet's, in presentation order
    std::int64_t end = 0;           // the latest pts + duration
    int width = 0, height = 0, sample_rate = 0, channels = 0;

    // From the first packet's time (or 0, for sound with encoder priming
    // before 0) to the end of the last.
    double seconds() const {
        if (pts.empty()) return 0;
        return double(end - std::max<std::int64_t>(pts.front(), 0)) * av_q2d(time_base);
    }
    double time(std::size_t k) const { return double(pts.at(k)) * av_q2d(time_base); }
};

struct Media {
    std::vector<MediaStream> streams;
    const MediaStream* first(AVMediaType type) const {
        for (const MediaStream& s : streams)
            if (s.type == type) return &s;
        return nullptr;
    }
};

namespace media_detail {
struct CloseInput {
    void operator()(AVFormatContext* c) const { avformat_close_input(&c); }
};
using Input = std::unique_ptr<AVFormatContext, CloseInput>;

// `format`: nullptr to probe, or "concat" for a list of files to join.
inline Input open(const std::string& path, const char* format) {
    av_log_set_level(AV_LOG_QUIET);
    AVDictionary* options = nullptr;
    if (format && std::string(format) == "concat") av_dict_set(&options, "safe", "0", 0);
    AVFormatContext* raw = nullptr;
    const int r = avformat_open_input(&raw, path.c_str(), format ? av_find_input_format(format) : nullptr, &options);
    av_dict_free(&options);
    if (r < 0) throw std::runtime_error("media_probe: cannot open " + path);
    Input in(raw);
    if (avformat_find_stream_info(in.get(), nullptr) < 0) throw std::runtime_error("media_probe: no streams in " + path);
    return in;
}
}  // namespace media_detail

// Every stream of the file and every packet's time, read through libavformat.
inline Media probe_media(const std::string& path, const char* format = nullptr) {
    media_detail::Input in = media_detail::open(path, format);
    Media m;
    for (unsigned i = 0; i < in->nb_streams; ++i) {
        const AVStream* st = in->streams[i];
        MediaStream s;
        s.codec = avcodec_get_name(st->codecpar->codec_id);
        s.type = st->codecpar->codec_type;
        s.time_base = st->time_base;
        s.width = st->codecpar->width;
        s.height = st->codecpar->height;
        s.sample_rate = st->codecpar->sample_rate;
        s.channels = st->codecpar->ch_layout.nb_channels;
        m.streams.push_back(s);
    }
    AVPacket* packet = av_packet_alloc();
    while (av_read_frame(in.get(), packet) >= 0) {
        MediaStream& s = m.streams.at(std::size_t(packet->stream_index));
        const std::int64_t pts = packet->pts != AV_NOPTS_VALUE ? packet->pts : packet->dts;
        s.pts.push_back(pts);
        s.end = std::max(s.end, pts + packet->duration);
        av_packet_unref(packet);
    }
    av_packet_free(&packet);
    for (MediaStream& s : m.streams) std::sort(s.pts.begin(), s.pts.end());
    return m;
}

// The first sound stream decoded, channels averaged; sets `rate`. Samples
// the container marks as encoder priming are dropped by the decoder, so
// sample i plays at i / rate.
inline std::vector<float> decode_sound(const std::string& path, int& rate, const char* format = nullptr) {
    media_detail::Input in = media_detail::open(path, format);
    const AVCodec* decoder = nullptr;
    const int index = av_find_best_stream(in.get(), AVMEDIA_TYPE_AUDIO, -1, -1, &decoder, 0);
    if (index < 0 || !decoder) throw std::runtime_error("media_probe: no sound in " + path);
    AVCodecContext* c = avcodec_alloc_context3(decoder);
    avcodec_parameters_to_context(c, in->streams[index]->codecpar);
    if (avcodec_open2(c, decoder, nullptr) < 0) throw std::runtime_error("media_probe: cannot decode " + path);
    std::vector<float> samples;
    AVPacket* packet = av_packet_alloc();
    AVFrame* frame = av_frame_alloc();
    auto drain = [&] {
        while (avcodec_receive_frame(c, frame) >= 0) {
            const int channels = frame->ch_layout.nb_channels;
            const auto fmt = AVSampleFormat(frame->format);
            const bool planar = av_sample_fmt_is_planar(fmt);
            for (int i = 0; i < frame->nb_samples; ++i) {
                double sum = 0;
                for (int ch = 0; ch < channels; ++ch) {
                    const int plane = planar ? ch : 0, at = planar ? i : i * channels + ch;
                    const std::uint8_t* d = frame->extended_data[plane];
                    switch (av_get_packed_sample_fmt(fmt)) {
                        case AV_SAMPLE_FMT_FLT: sum += reinterpret_cast<const float*>(d)[at]; break;
                        case AV_SAMPLE_FMT_S16: sum += reinterpret_cast<const std::int16_t*>(d)[at] / 32768.0; break;
                        case AV_SAMPLE_FMT_S32: sum += reinterpret_cast<const std::int32_t*>(d)[at] / 2147483648.0; break;
                        default: throw std::runtime_error("media_probe: unexpected sample format");
                    }
                }
                samples.push_back(float(sum / channels));
            }
        }
    };
    while (av_read_frame(in.get(), packet) >= 0) {
        if (packet->stream_index == index) avcodec_send_packet(c, packet);
        av_packet_unref(packet);
        drain();
    }
    avcodec_send_packet(c, nullptr);
    drain();
    rate = c->sample_rate;
    av_frame_free(&frame);
    av_packet_free(&packet);
    avcodec_free_context(&c);
    return samples;
}

// The first sample louder than `level` (-1: none), as seconds.
inline double first_loud(const std::vector<float>& samples, int rate, float level = 0.25f) {
    for (std::size_t i = 0; i < samples.size(); ++i)
        if (std::fabs(samples[i]) > level) return double(i) / rate;
    return -1;
}

// A 16-bit PCM WAV of `seconds` at `rate` Hz with `channels` channels:
// silence, then a 1 kHz tone at amplitude 0.8 from `tone_from` seconds on
// (0: from the start; a tone after silence is a click the tests can find).
inline void write_test_wav(const std::string& path, double seconds, double tone_from = 0, int rate = 48000,
                           int channels = 1) {
    const auto frames = std::uint32_t(std::lround(seconds * rate));
    const std::uint32_t data_bytes = frames * std::uint32_t(channels) * 2;
    std::string bytes;
    auto u32 = [&](std::uint32_t v) {
        for (int i = 0; i < 4; ++i) bytes.push_back(char((v >> (8 * i)) & 0xff));
    };
    auto u16 = [&](std::uint16_t v) {
        bytes.push_back(char(v & 0xff));
        bytes.push_back(char(v >> 8));
    };
    bytes += "RIFF";
    u32(36 + data_bytes);
    bytes += "WAVEfmt ";
    u32(16);
    u16(1);  // PCM
    u16(std::uint16_t(channels));
    u32(std::uint32_t(rate));
    u32(std::uint32_t(rate * channels * 2));
    u16(std::uint16_t(channels * 2));
    u16(16);
    bytes += "data";
    u32(data_bytes);
    const double pi = 3.14159265358979323846;
    for (std::uint32_t i = 0; i < frames; ++i) {
        const double t = double(i) / rate;
        const double v = t >= tone_from ? 0.8 * std::sin(2 * pi * 1000 * (t - tone_from)) : 0.0;
        for (int ch = 0; ch < channels; ++ch) u16(std::uint16_t(std::int16_t(std::lround(v * 32767))));
    }
    std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

}  // namespace emoface::testing
