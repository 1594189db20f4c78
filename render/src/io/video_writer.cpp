#include "emoface/render/video_writer.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/audio_fifo.h>
#include <libavutil/channel_layout.h>
#include <libavutil/error.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
#include <libavutil/rational.h>
#include <libavutil/samplefmt.h>
#include <libswresample/swresample.h>
#include <libswscale/swscale.h>
}

#include <algorithm>
#include <cctype>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <exception>
#include <filesystem>
#include <mutex>
#include <thread>

#include "emoface/common/atomic_file.h"
#include "emoface/common/error.h"
#include "emoface/common/input_file.h"
#include "emoface/common/output_batch.h"
#include "emoface/render/image_io.h"

namespace emoface::render {

namespace {

std::string lower_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

std::string av_error(int code) {
    char text[AV_ERROR_MAX_STRING_SIZE] = {};
    av_strerror(code, text, sizeof text);
    return text;
}

// What each extension holds. The default crf: x264's 23 smears the fine
// shading of wrinkles and pores at 720p, 20 keeps it; 31 is libvpx's own
// advice for VP9 at HD sizes.
struct Container {
    const char* extension;
    const char* muxer;
    const char* video_encoder;  // FFmpeg's name
    const char* video_name;     // VideoWriter::codec()
    int crf_max;                // -1: no crf
    int crf_default;
    const char* audio_encoder;
    const char* audio_name;
};

constexpr Container kContainers[] = {
    {".mp4", "mp4", "libx264", "H.264", 51, 20, "aac", "AAC"},
    {".mkv", "matroska", "libx264", "H.264", 51, 20, "aac", "AAC"},
    {".webm", "webm", "libvpx-vp9", "VP9", 63, 31, "libopus", "Opus"},
    {".avi", "avi", "mjpeg", "MJPG", -1, -1, "pcm_s16le", "PCM"},
};

const Container* container_for(const std::string& path) {
    const std::string ext = lower_extension(path);
    for (const Container& c : kContainers)
        if (ext == c.extension) return &c;
    return nullptr;
}

// FFmpeg's logging (tens of lines from libx264 or a muxer that fails to
// open) silenced before the first use: a failure is summarised in one line
// of ours. EMOFACE_FFMPEG_LOGLEVEL (an AV_LOG_* number) keeps it, for
// debugging.
void quiet_ffmpeg() {
    static const bool done = [] {
        const char* level = std::getenv("EMOFACE_FFMPEG_LOGLEVEL");
        av_log_set_level(level ? std::atoi(level) : AV_LOG_QUIET);
        return true;
    }();
    (void)done;
}

struct FreeFormatInput {
    void operator()(AVFormatContext* c) const { avformat_close_input(&c); }
};
struct FreeCodec {
    void operator()(AVCodecContext* c) const { avcodec_free_context(&c); }
};
struct FreeFrame {
    void operator()(AVFrame* f) const { av_frame_free(&f); }
};
struct FreePacket {
    void operator()(AVPacket* p) const { av_packet_free(&p); }
};
struct FreeSwr {
    void operator()(SwrContext* s) const { swr_free(&s); }
};
struct FreeSws {
    void operator()(SwsContext* s) const { sws_freeContext(s); }
};
struct FreeFifo {
    void operator()(AVAudioFifo* f) const { av_audio_fifo_free(f); }
};
// An output context with its file: the file closed, then the context freed.
struct FreeFormatOutput {
    void operator()(AVFormatContext* c) const {
        if (c->pb && !(c->oformat->flags & AVFMT_NOFILE)) avio_closep(&c->pb);
        avformat_free_context(c);
    }
};
using CodecPtr = std::unique_ptr<AVCodecContext, FreeCodec>;
using FramePtr = std::unique_ptr<AVFrame, FreeFrame>;
using PacketPtr = std::unique_ptr<AVPacket, FreePacket>;

FramePtr new_frame() {
    FramePtr f(av_frame_alloc());
    if (!f) throw std::bad_alloc();
    return f;
}
PacketPtr new_packet() {
    PacketPtr p(av_packet_alloc());
    if (!p) throw std::bad_alloc();
    return p;
}

// A sound file, decoded frame by frame and converted to the encoder's
// sample format, rate and channels. Opening it decodes its first frame, so
// a file FFmpeg can open but not decode is refused before any work.
class AudioSource {
public:
    explicit AudioSource(const std::string& path) : shown_(OutputBatch::shown_path(path)) {
        quiet_ffmpeg();
        check_input_file(path, kMaxAudioFileBytes, "render");
        AVFormatContext* raw = nullptr;
        if (const int r = avformat_open_input(&raw, path.c_str(), nullptr, nullptr); r < 0)
            bad("a sound file FFmpeg reads", av_error(r));
        input_.reset(raw);
        if (const int r = avformat_find_stream_info(input_.get(), nullptr); r < 0)
            bad("a sound file FFmpeg reads", av_error(r));
        const AVCodec* decoder = nullptr;
        stream_ = av_find_best_stream(input_.get(), AVMEDIA_TYPE_AUDIO, -1, -1, &decoder, 0);
        if (stream_ == AVERROR_STREAM_NOT_FOUND) {
            std::string kinds;
            for (unsigned i = 0; i < input_->nb_streams; ++i) {
                const char* kind = av_get_media_type_string(input_->streams[i]->codecpar->codec_type);
                kinds += (i ? ", " : "") + std::string(kind ? kind : "unknown");
            }
            bad("a sound stream", kinds.empty() ? "no streams" : fmt::format("none (streams: {})", kinds));
        }
        if (stream_ < 0 || !decoder)
            bad("a sound stream FFmpeg decodes",
                fmt::format("{} with no decoder here",
                            avcodec_get_name(input_->streams[std::max(stream_, 0)]->codecpar->codec_id)));
        decoder_.reset(avcodec_alloc_context3(decoder));
        if (!decoder_) throw std::bad_alloc();
        if (avcodec_parameters_to_context(decoder_.get(), input_->streams[stream_]->codecpar) < 0 ||
            avcodec_open2(decoder_.get(), decoder, nullptr) < 0)
            bad("a sound stream FFmpeg decodes", fmt::format("{} that its decoder refuses", decoder->name));
        packet_ = new_packet();
        frame_ = new_frame();
        if (!next_frame()) bad("sound", "no samples (the stream is empty)");
        pending_ = true;
        if (decoder_->sample_rate <= 0 || decoder_->ch_layout.nb_channels <= 0)
            bad("sound", "no sample rate or channels");
    }

    int sample_rate() const { return decoder_->sample_rate; }
    int channels() const { return decoder_->ch_layout.nb_channels; }
    const std::string& shown_path() const { return shown_; }

    // Converts to `rate` Hz, `layout`, `format` from now on.
    void set_output(const AVChannelLayout& layout, AVSampleFormat format, int rate) {
        AVChannelLayout in{};
        if (decoder_->ch_layout.order == AV_CHANNEL_ORDER_UNSPEC)
            av_channel_layout_default(&in, decoder_->ch_layout.nb_channels);
        else
            av_channel_layout_copy(&in, &decoder_->ch_layout);
        SwrContext* swr = nullptr;
        // 5.1 takes the layouts non-const; it only reads them.
        const int r = swr_alloc_set_opts2(&swr, const_cast<AVChannelLayout*>(&layout), format, rate, &in, decoder_->sample_fmt,
                                          decoder_->sample_rate, 0, nullptr);
        av_channel_layout_uninit(&in);
        converter_.reset(swr);
        if (r < 0 || swr_init(converter_.get()) < 0)
            bad("sound that can be resampled", fmt::format("{} channels at {} Hz", channels(), sample_rate()));
        av_channel_layout_copy(&out_layout_, &layout);
        out_format_ = format;
        out_rate_ = rate;
    }
    ~AudioSource() { av_channel_layout_uninit(&out_layout_); }

    // Appends the next decoded stretch to `fifo`, converted; false once the
    // file (and the resampler's tail) is exhausted.
    bool decode_into(AVAudioFifo* fifo) {
        if (done_) return false;
        const bool have = pending_ || next_frame();
        pending_ = false;
        const int in_samples = have ? frame_->nb_samples : 0;
        FramePtr out = new_frame();
        av_channel_layout_copy(&out->ch_layout, &out_layout_);
        out->format = out_format_;
        out->sample_rate = out_rate_;
        out->nb_samples = std::max(swr_get_out_samples(converter_.get(), in_samples), 1);
        if (av_frame_get_buffer(out.get(), 0) < 0) throw std::bad_alloc();
        // Raw planes, not swr_convert_frame: WAV's frames carry a layout of
        // unspecified order that it would call a changed input. nullptr at
        // the end drains the resampler.
        const int n = swr_convert(converter_.get(), out->extended_data, out->nb_samples,
                                  have ? const_cast<const std::uint8_t**>(frame_->extended_data) : nullptr,
                                  in_samples);
        if (n < 0) bad("sound that can be resampled", av_error(n));
        if (n > 0 && av_audio_fifo_write(fifo, reinterpret_cast<void**>(out->extended_data), n) < n)
            throw std::bad_alloc();
        if (!have) done_ = true;
        return have || n > 0;
    }

private:
    [[noreturn]] void bad(const std::string& expected, const std::string& found) const {
        fail<InputError>("render: {}: expected {}, found {}", shown_, expected, found);
    }

    bool next_frame() {
        for (;;) {
            int r = avcodec_receive_frame(decoder_.get(), frame_.get());
            if (r == 0) return true;
            if (r == AVERROR_EOF) return false;
            if (r != AVERROR(EAGAIN)) bad("decodable sound", av_error(r));
            r = av_read_frame(input_.get(), packet_.get());
            if (r == AVERROR_EOF) {
                avcodec_send_packet(decoder_.get(), nullptr);
                continue;
            }
            if (r < 0) bad("readable sound", av_error(r));
            if (packet_->stream_index == stream_) r = avcodec_send_packet(decoder_.get(), packet_.get());
            av_packet_unref(packet_.get());
            if (r < 0 && r != AVERROR(EAGAIN)) bad("decodable sound", av_error(r));
        }
    }

    std::string shown_;
    std::unique_ptr<AVFormatContext, FreeFormatInput> input_;
    CodecPtr decoder_;
    int stream_ = -1;
    PacketPtr packet_;
    FramePtr frame_;
    bool pending_ = false, done_ = false;
    std::unique_ptr<SwrContext, FreeSwr> converter_;
    AVChannelLayout out_layout_{};
    AVSampleFormat out_format_ = AV_SAMPLE_FMT_NONE;
    int out_rate_ = 0;
};

// Frames waiting for the encoder: enough to smooth a slow frame, few enough
// that 1080p frames cost little memory.
constexpr std::size_t kQueuedFrames = 4;

}  // namespace

struct VideoWriter::Impl {
    const Container* container = nullptr;
    std::string shown;  // the user's path, for messages
    AVRational fps{25, 1};
    std::unique_ptr<AVFormatContext, FreeFormatOutput> out;
    CodecPtr video, audio;
    AVStream* video_stream = nullptr;
    AVStream* audio_stream = nullptr;
    std::unique_ptr<SwsContext, FreeSws> to_yuv;
    FramePtr yuv;
    PacketPtr packet;
    std::int64_t encoded = 0;  // video frames sent to the encoder

    std::unique_ptr<AudioSource> source;
    std::unique_ptr<AVAudioFifo, FreeFifo> fifo;
    std::int64_t first_frame = 0;
    double audio_offset = 0;
    std::int64_t audio_first = 0;  // the source sample under the file's first frame
    std::int64_t audio_sent = 0;   // samples sent to the encoder
    std::int64_t skip = 0;         // source samples still to drop before audio_first
    int audio_frame = 1024;        // samples per encoded frame
    bool small_last_frame = true;

    std::thread thread;
    std::mutex mutex;
    std::condition_variable changed;
    std::deque<ImageRGBA8> queue;
    bool closing = false, abandoned = false;
    std::exception_ptr error;

    ~Impl() {
        if (thread.joinable()) {
            {
                std::lock_guard<std::mutex> lock(mutex);
                abandoned = true;
            }
            changed.notify_all();
            thread.join();
        }
    }

    // The source sample (at the encoder's rate) under the animation's frame k.
    std::int64_t sample_at_frame(std::int64_t k) const {
        const long double seconds = static_cast<long double>(k) * fps.den / fps.num - audio_offset;
        return std::llroundl(seconds * audio->sample_rate);
    }

    void open_video(int width, int height, int crf) {
        const AVCodec* codec = avcodec_find_encoder_by_name(container->video_encoder);
        if (!codec)
            fail<EnvironmentError>("render: {}: FFmpeg here has no {} encoder for {} (install Debian's "
                                   "libavcodec59, which has it)",
                                   shown, container->video_encoder, container->video_name);
        video.reset(avcodec_alloc_context3(codec));
        if (!video) throw std::bad_alloc();
        AVCodecContext& c = *video;
        c.width = width;
        c.height = height;
        c.time_base = av_inv_q(fps);
        c.framerate = fps;
        c.sample_aspect_ratio = {1, 1};
        const bool jpeg = codec->id == AV_CODEC_ID_MJPEG;
        // Motion-JPEG is full-range BT.601 by convention; H.264 and VP9 the
        // limited-range BT.709 of HD video, tagged so players agree.
        c.pix_fmt = jpeg ? AV_PIX_FMT_YUVJ420P : AV_PIX_FMT_YUV420P;
        c.color_range = jpeg ? AVCOL_RANGE_JPEG : AVCOL_RANGE_MPEG;
        c.colorspace = jpeg ? AVCOL_SPC_BT470BG : AVCOL_SPC_BT709;
        c.color_primaries = AVCOL_PRI_BT709;
        c.color_trc = AVCOL_TRC_BT709;
        if (out->oformat->flags & AVFMT_GLOBALHEADER) c.flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
        AVDictionary* options = nullptr;
        if (jpeg) {
            c.flags |= AV_CODEC_FLAG_QSCALE;
            c.global_quality = FF_QP2LAMBDA * 3;
        } else {
            av_dict_set_int(&options, "crf", crf, 0);
            if (codec->id == AV_CODEC_ID_VP9) {
                c.bit_rate = 0;  // constant quality: crf alone
                av_dict_set(&options, "deadline", "good", 0);
                av_dict_set_int(&options, "cpu-used", 4, 0);
                av_dict_set_int(&options, "row-mt", 1, 0);
            }
        }
        const int r = avcodec_open2(&c, codec, &options);
        av_dict_free(&options);
        if (r < 0)
            fail<EnvironmentError>("render: {}: FFmpeg's {} encoder refused {}x{} at {}/{} frames/s: {}", shown,
                                   container->video_encoder, width, height, fps.num, fps.den, av_error(r));
        video_stream = avformat_new_stream(out.get(), nullptr);
        if (!video_stream) throw std::bad_alloc();
        video_stream->time_base = c.time_base;
        video_stream->avg_frame_rate = fps;
        if (avcodec_parameters_from_context(video_stream->codecpar, &c) < 0) throw std::bad_alloc();

        to_yuv.reset(sws_getContext(width, height, AV_PIX_FMT_RGBA, width, height, c.pix_fmt,
                                    SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT, nullptr, nullptr,
                                    nullptr));
        if (!to_yuv) fail<InternalError>("render: {}: swscale has no RGBA to YUV 4:2:0 conversion", shown);
        const int* matrix = sws_getCoefficients(jpeg ? SWS_CS_ITU601 : SWS_CS_ITU709);
        sws_setColorspaceDetails(to_yuv.get(), sws_getCoefficients(SWS_CS_DEFAULT), 1, matrix, jpeg ? 1 : 0, 0,
                                 1 << 16, 1 << 16);
        yuv = new_frame();
        yuv->format = c.pix_fmt;
        yuv->width = width;
        yuv->height = height;
        if (av_frame_get_buffer(yuv.get(), 0) < 0) throw std::bad_alloc();
        packet = new_packet();
    }

    void open_audio(const std::string& path) {
        source = std::make_unique<AudioSource>(path);
        const AVCodec* codec = avcodec_find_encoder_by_name(container->audio_encoder);
        if (!codec)
            fail<EnvironmentError>("render: {}: FFmpeg here has no {} encoder for {} sound (install Debian's "
                                   "libavcodec59, which has it)",
                                   shown, container->audio_encoder, container->audio_name);
        audio.reset(avcodec_alloc_context3(codec));
        if (!audio) throw std::bad_alloc();
        AVCodecContext& c = *audio;
        // The source's rate where the encoder takes it (Opus: 48, 24, 16, 12
        // or 8 kHz), else 48 kHz; mono stays mono, more channels become two.
        int rate = source->sample_rate();
        if (codec->supported_samplerates) {
            bool listed = false;
            for (const int* r = codec->supported_samplerates; *r; ++r) listed |= *r == rate;
            if (!listed) rate = 48000;
        }
        c.sample_rate = rate;
        av_channel_layout_default(&c.ch_layout, std::min(source->channels(), 2));
        c.sample_fmt = codec->sample_fmts ? codec->sample_fmts[0] : AV_SAMPLE_FMT_S16;
        c.bit_rate = 64000 * c.ch_layout.nb_channels;
        c.time_base = {1, rate};
        if (out->oformat->flags & AVFMT_GLOBALHEADER) c.flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
        if (const int r = avcodec_open2(&c, codec, nullptr); r < 0)
            fail<EnvironmentError>("render: {}: FFmpeg's {} encoder refused {} channels at {} Hz: {}", shown,
                                   container->audio_encoder, c.ch_layout.nb_channels, rate, av_error(r));
        const bool variable = codec->capabilities & AV_CODEC_CAP_VARIABLE_FRAME_SIZE;
        audio_frame = c.frame_size > 0 && !variable ? c.frame_size : 1024;
        small_last_frame = variable || (codec->capabilities & AV_CODEC_CAP_SMALL_LAST_FRAME);
        audio_stream = avformat_new_stream(out.get(), nullptr);
        if (!audio_stream) throw std::bad_alloc();
        audio_stream->time_base = c.time_base;
        if (avcodec_parameters_from_context(audio_stream->codecpar, &c) < 0) throw std::bad_alloc();

        source->set_output(c.ch_layout, c.sample_fmt, rate);
        fifo.reset(av_audio_fifo_alloc(c.sample_fmt, c.ch_layout.nb_channels, audio_frame * 4));
        if (!fifo) throw std::bad_alloc();
        audio_first = sample_at_frame(first_frame);
        if (audio_first > 0) skip = audio_first;
        else append_silence(-audio_first);
    }

    void append_silence(std::int64_t count) {
        while (count > 0) {
            const int n = int(std::min<std::int64_t>(count, 1 << 16));
            FramePtr quiet = silent_frame(n);
            if (av_audio_fifo_write(fifo.get(), reinterpret_cast<void**>(quiet->extended_data), n) < n)
                throw std::bad_alloc();
            count -= n;
        }
    }

    FramePtr silent_frame(int samples) const {
        FramePtr f = new_frame();
        f->format = audio->sample_fmt;
        av_channel_layout_copy(&f->ch_layout, &audio->ch_layout);
        f->sample_rate = audio->sample_rate;
        f->nb_samples = samples;
        if (av_frame_get_buffer(f.get(), 0) < 0) throw std::bad_alloc();
        av_samples_set_silence(f->extended_data, 0, samples, f->ch_layout.nb_channels,
                               AVSampleFormat(f->format));
        return f;
    }

    // Makes `count` samples ready in the fifo: the source's, after the
    // stretch before audio_first is dropped, then silence.
    void fill(int count) {
        while (av_audio_fifo_size(fifo.get()) < count) {
            if (!source->decode_into(fifo.get())) {
                skip = 0;
                append_silence(count - av_audio_fifo_size(fifo.get()));
                break;
            }
            if (skip > 0) {
                const int drop = int(std::min<std::int64_t>(skip, av_audio_fifo_size(fifo.get())));
                av_audio_fifo_drain(fifo.get(), drop);
                skip -= drop;
            }
        }
    }

    // Encodes the sound up to (not past) the end of the animation's frame
    // first_frame + frames - 1; `last`: a final, shorter frame too.
    void encode_audio(std::int64_t frames, bool last) {
        const std::int64_t end = sample_at_frame(first_frame + frames) - audio_first;
        while (audio_sent < end) {
            const std::int64_t left = end - audio_sent;
            if (left < audio_frame && !last) break;
            const int n = int(std::min<std::int64_t>(left, audio_frame));
            const int padded = small_last_frame ? n : audio_frame;
            fill(n);
            FramePtr f = silent_frame(padded);
            if (av_audio_fifo_read(fifo.get(), reinterpret_cast<void**>(f->extended_data), n) < n)
                fail<InternalError>("render: {}: the sound queue ran short", shown);
            f->pts = audio_sent;
            send(audio.get(), audio_stream, f.get());
            audio_sent += n;
        }
    }

    void encode_video(const ImageRGBA8& image) {
        if (av_frame_make_writable(yuv.get()) < 0) throw std::bad_alloc();
        const std::uint8_t* rows[1] = {image.pixels.data()};
        const int stride[1] = {image.width * 4};
        sws_scale(to_yuv.get(), rows, stride, 0, image.height, yuv->data, yuv->linesize);
        yuv->pts = encoded++;
        send(video.get(), video_stream, yuv.get());
        if (audio) encode_audio(encoded, false);
    }

    // Sends a frame (nullptr: the end) and writes every packet it gives.
    void send(AVCodecContext* codec, AVStream* stream, const AVFrame* frame) {
        if (const int r = avcodec_send_frame(codec, frame); r < 0)
            fail("render: {}: the {} encoder failed: {}", shown, codec->codec->name, av_error(r));
        for (;;) {
            const int r = avcodec_receive_packet(codec, packet.get());
            if (r == AVERROR(EAGAIN) || r == AVERROR_EOF) return;
            if (r < 0) fail("render: {}: the {} encoder failed: {}", shown, codec->codec->name, av_error(r));
            // Every frame lasts 1 / fps (libx264 leaves it unset).
            if (codec == video.get() && packet->duration == 0) packet->duration = 1;
            av_packet_rescale_ts(packet.get(), codec->time_base, stream->time_base);
            packet->stream_index = stream->index;
            if (const int w = av_interleaved_write_frame(out.get(), packet.get()); w < 0)
                fail("render: {}: writing the video failed: {}", shown, av_error(w));
        }
    }

    void finish() {
        send(video.get(), video_stream, nullptr);
        if (audio) {
            encode_audio(encoded, true);
            send(audio.get(), audio_stream, nullptr);
        }
        if (const int r = av_write_trailer(out.get()); r < 0)
            fail("render: {}: finishing the video failed: {}", shown, av_error(r));
        if (const int r = avio_closep(&out->pb); r < 0)
            fail("render: {}: closing the video failed: {}", shown, av_error(r));
    }

    // The encoder thread: frames from the queue until close() or the
    // destructor; a failure is kept for the caller.
    void run() {
        try {
            for (;;) {
                ImageRGBA8 image;
                {
                    std::unique_lock<std::mutex> lock(mutex);
                    changed.wait(lock, [&] { return abandoned || closing || !queue.empty(); });
                    if (abandoned) return;
                    if (queue.empty()) break;
                    image = std::move(queue.front());
                    queue.pop_front();
                }
                changed.notify_all();
                encode_video(image);
            }
            finish();
        } catch (...) {
            std::lock_guard<std::mutex> lock(mutex);
            error = std::current_exception();
        }
        changed.notify_all();
    }
};

const char* VideoWriter::extensions() { return ".mp4, .mkv, .webm, .avi"; }

bool VideoWriter::has_video_extension(const std::string& path) { return container_for(path) != nullptr; }

void VideoWriter::check(const std::string& path, int width, int height, const VideoOptions& options) {
    const std::string shown = OutputBatch::shown_path(path);
    const Container* c = container_for(path);
    if (!c)
        fail<InputError>("render: {}: video output must end in {}, got '{}'", shown, extensions(),
                         lower_extension(path));
    if (width <= 0 || height <= 0 || width % 2 || height % 2)
        fail<InputError>("render: {}: video frames must have a positive even size, got {}x{}", shown, width,
                         height);
    if (!(options.fps >= kMinVideoFps && options.fps <= kMaxVideoFps))
        fail<InputError>("render: {}: frame rate must be {}..{} frames per second, got {}", shown, kMinVideoFps,
                         kMaxVideoFps, options.fps);
    if (options.crf != -1) {
        if (c->crf_max < 0)
            fail<InputError>("render: {}: {} video has no crf (constant rate factor); use .mp4, .mkv or .webm",
                             shown, c->extension);
        if (options.crf < 0 || options.crf > c->crf_max)
            fail<InputError>("render: {}: expected a crf of 0..{} for {}, got {}", shown, c->crf_max,
                             c->video_name, options.crf);
    }
    if (!std::isfinite(options.audio_offset))
        fail<InputError>("render: {}: expected a finite sound offset, got {}", shown, options.audio_offset);
    if (options.first_frame < 0)
        fail<InputError>("render: {}: expected a first frame >= 0, got {}", shown, options.first_frame);
    if (!options.audio.empty()) AudioSource probe(options.audio);
}

VideoWriter::VideoWriter(const std::string& path, int width, int height, const VideoOptions& options)
    : impl_(std::make_unique<Impl>()), path_(path), width_(width), height_(height) {
    check(path, width, height, options);
    quiet_ffmpeg();
    Impl& m = *impl_;
    m.container = container_for(path);
    m.shown = OutputBatch::shown_path(path);
    m.fps = av_d2q(options.fps, 1001000);
    m.first_frame = options.first_frame;
    m.audio_offset = options.audio_offset;
    crf_ = m.container->crf_max < 0 ? -1 : options.crf >= 0 ? options.crf : m.container->crf_default;
    codec_ = m.container->video_name;

    temp_path_ = temporary_path_for(path_);
    AVFormatContext* raw = nullptr;
    if (const int r = avformat_alloc_output_context2(&raw, nullptr, m.container->muxer, temp_path_.c_str()); r < 0)
        fail<EnvironmentError>("render: {}: FFmpeg here has no {} muxer: {}", m.shown, m.container->muxer,
                               av_error(r));
    m.out.reset(raw);
    m.open_video(width, height, crf_);
    if (!options.audio.empty()) {
        m.open_audio(options.audio);
        audio_codec_ = m.container->audio_name;
    }
    if (const int r = avio_open(&m.out->pb, temp_path_.c_str(), AVIO_FLAG_WRITE); r < 0)
        fail<InputError>("render: {}: expected a writable file, found {}", m.shown, av_error(r));
    AVDictionary* options_out = nullptr;
    // The index before the data, so a browser plays the file while it loads.
    if (std::string(m.container->muxer) == "mp4") av_dict_set(&options_out, "movflags", "+faststart", 0);
    const int r = avformat_write_header(m.out.get(), &options_out);
    av_dict_free(&options_out);
    if (r < 0) {
        m.out.reset();
        discard_temporary(temp_path_);
        fail<EnvironmentError>("render: {}: FFmpeg's {} muxer refused the streams: {}", m.shown, m.container->muxer,
                               av_error(r));
    }
    m.thread = std::thread([&m] { m.run(); });
}

VideoWriter::~VideoWriter() {
    impl_.reset();  // stops and joins the encoder thread, closes the file
    // Not closed, or closing failed: no partial file (after close() the
    // temporary name is gone).
    discard_temporary(temp_path_);
}

void VideoWriter::write(const ImageRGBA8& frame) { write(ImageRGBA8(frame)); }

void VideoWriter::write(ImageRGBA8&& frame) {
    Impl& m = *impl_;
    if (closed_) fail("render: {}: the video is already closed", m.shown);
    if (frame.width != width_ || frame.height != height_ || frame.pixels.size() != std::size_t(width_) * height_ * 4)
        fail("render: {}: frame {} is {}x{}, the video is {}x{}", m.shown, frames_, frame.width, frame.height, width_,
             height_);
    {
        std::unique_lock<std::mutex> lock(m.mutex);
        m.changed.wait(lock, [&] { return m.error || m.queue.size() < kQueuedFrames; });
        if (m.error) std::rethrow_exception(m.error);
        m.queue.push_back(std::move(frame));
    }
    m.changed.notify_all();
    ++frames_;
}

std::string VideoWriter::close() {
    Impl& m = *impl_;
    if (closed_) fail("render: {}: the video is already closed", m.shown);
    closed_ = true;
    {
        std::lock_guard<std::mutex> lock(m.mutex);
        m.closing = true;
    }
    m.changed.notify_all();
    m.thread.join();
    if (m.error) {
        discard_temporary(temp_path_);
        std::rethrow_exception(m.error);
    }
    std::error_code ec;
    const auto size = std::filesystem::file_size(temp_path_, ec);
    if (ec || size == 0) {
        discard_temporary(temp_path_);
        fail("render: {}: the encoder wrote nothing", m.shown);
    }
    commit_temporary(temp_path_, path_, "render");
    return path_;
}

FrameSequenceWriter::FrameSequenceWriter(std::string pattern, int first_index)
    : pattern_(std::move(pattern)), next_(first_index) {
    int conversions = 0;
    for (std::size_t i = 0; i < pattern_.size(); ++i) {
        if (pattern_[i] != '%') continue;
        if (i + 1 < pattern_.size() && pattern_[i + 1] == '%') {
            ++i;
            continue;
        }
        std::size_t j = i + 1;
        // Zero padding only: '-', '+' and ' ' would put spaces or signs in
        // file names.
        while (j < pattern_.size() && pattern_[j] == '0') ++j;
        while (j < pattern_.size() && std::isdigit(static_cast<unsigned char>(pattern_[j]))) ++j;
        if (j >= pattern_.size() || pattern_[j] != 'd' || j - i > 6)
            fail<InputError>("render: frame pattern '{}': only %d conversions (like %04d) are "
                             "allowed, found one at character {}",
                             pattern_, i + 1);
        ++conversions;
        i = j;
    }
    if (conversions != 1)
        fail<InputError>("render: frame pattern '{}': needs exactly one %d (like face_%04d.png), "
                         "found {}",
                         pattern_, conversions);
    // All frames in one folder: the number goes in the file name.
    if (std::filesystem::path(path_for(0)).parent_path() != std::filesystem::path(path_for(1)).parent_path())
        fail<InputError>("render: frame pattern '{}': the %d must be in the file name, not in a folder's",
                         pattern_);
    if (std::filesystem::path(path_for(0)).filename().empty())
        fail<InputError>("render: frame pattern '{}': expected a file name after the last '/'", pattern_);
}

std::string FrameSequenceWriter::path_for(int index) const {
    char buf[4096];
    const int n = std::snprintf(buf, sizeof buf, pattern_.c_str(), index);
    if (n < 0 || std::size_t(n) >= sizeof buf)
        fail<InputError>("render: frame pattern '{}' gives a path that is too long", pattern_);
    return buf;
}

std::string FrameSequenceWriter::write(const ImageRGBA8& frame) {
    const std::string path = path_for(next_);
    write_image(path, frame);
    ++next_;
    return path;
}

}  // namespace emoface::render
