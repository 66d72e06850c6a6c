// test_video.cpp - `gravscale video` end to end on clips rendered here with
// known truth: an orange ball of known diameter thrown on a grey background,
// drawn with sub-pixel accuracy at a known scale q (m/px) under g = 9.81, so
// a_px = g / q. Checks the diameter (2 %) and q of each flight for FFV1 and
// MJPG clips and an image sequence; a slow-motion clip stored at a false rate
// (--fps and the com.android.capture.fps tag, written here with libavformat);
// the H.264 end-of-stream timestamps; the frame source's own H.264 decoding
// against OpenCV's, pixel for pixel and time for time; corrupt, empty, truncated and missing
// files; a clip without a ball; the overlay and the plot.
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <spawn.h>
#include <string>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

extern "C" {
#include <libavformat/avformat.h>
#include <libavutil/dict.h>
#include "unity.h"
}

#include "frame_source.hpp"
#include "gs_test_util.hpp"

#ifndef GS_PROGRAM
#error "GS_PROGRAM (path of the gravscale program) must be defined"
#endif

extern char **environ;

void setUp(void) {}
void tearDown(void) {}

namespace {

using gs_test::a_px;
using gs_test::ball_at;
using gs_test::d_px;
using gs_test::draw_disc;
using gs_test::lines_of;
using gs_test::num;
using gs_test::slurp;

std::string g_dir;
int g_seq = 0;

// ---- rendering ---------------------------------------------------------------

// the ball scene (gs_test::BallScene) and its frame rates
struct Scene : gs_test::BallScene {
    double true_fps = 60.0;       // frames per second of real time
    double stored_fps = 60.0;     // the rate written into the file
    bool ball = true;
};

cv::Mat render_frame(const Scene &s, double t, bool *more)
{
    cv::Mat img(s.height, s.width, CV_8UC3, cv::Scalar(128, 128, 128));
    double x, y;
    bool visible;
    *more = ball_at(s, t, x, y, visible);
    if (s.ball && visible && *more) draw_disc(img, x, y, 0.5 * d_px(s), cv::Vec3b(0, 130, 255));
    return img;
}

int scene_frames(const Scene &s)
{
    return static_cast<int>((s.empty_s + s.n_throws * (s.rest_s + s.flight_s) + s.rest_s) * s.true_fps);
}

std::string tmp(const std::string &name) { return g_dir + "/" + name; }

// false when this machine's FFmpeg cannot write the codec
bool write_clip(const std::string &path, const char *fourcc, const Scene &s)
{
    cv::VideoWriter w(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]),
                      s.stored_fps, cv::Size(s.width, s.height), true);
    if (!w.isOpened()) return false;
    int n = scene_frames(s);
    for (int i = 0; i < n; i++) {
        bool more;
        w.write(render_frame(s, i / s.true_fps, &more));
    }
    w.release();
    return true;
}

// Copy a file's streams into a new container with the Android slow-motion tag.
bool remux_with_capture_fps(const std::string &in, const std::string &out, const char *capture_fps)
{
    AVFormatContext *ic = nullptr, *oc = nullptr;
    if (avformat_open_input(&ic, in.c_str(), nullptr, nullptr) < 0) return false;
    bool ok = avformat_find_stream_info(ic, nullptr) >= 0 &&
              avformat_alloc_output_context2(&oc, nullptr, nullptr, out.c_str()) >= 0;
    for (unsigned i = 0; ok && i < ic->nb_streams; i++) {
        AVStream *os = avformat_new_stream(oc, nullptr);
        ok = os && avcodec_parameters_copy(os->codecpar, ic->streams[i]->codecpar) >= 0;
        if (ok) {
            os->codecpar->codec_tag = 0;
            os->time_base = ic->streams[i]->time_base;
            os->avg_frame_rate = ic->streams[i]->avg_frame_rate;
        }
    }
    AVDictionary *opts = nullptr;
    if (ok) {
        av_dict_set(&oc->metadata, "com.android.capture.fps", capture_fps, 0);
        av_dict_set(&opts, "movflags", "use_metadata_tags", 0);
        ok = avio_open(&oc->pb, out.c_str(), AVIO_FLAG_WRITE) >= 0 && avformat_write_header(oc, &opts) >= 0;
    }
    av_dict_free(&opts);
    AVPacket *pkt = av_packet_alloc();
    while (ok && av_read_frame(ic, pkt) >= 0) {
        AVStream *is = ic->streams[pkt->stream_index], *os = oc->streams[pkt->stream_index];
        av_packet_rescale_ts(pkt, is->time_base, os->time_base);
        pkt->pos = -1;
        ok = av_interleaved_write_frame(oc, pkt) >= 0;
        av_packet_unref(pkt);
    }
    av_packet_free(&pkt);
    if (ok) ok = av_write_trailer(oc) >= 0;
    if (oc) {
        if (oc->pb) avio_closep(&oc->pb);
        avformat_free_context(oc);
    }
    avformat_close_input(&ic);
    return ok;
}

void write_bytes(const std::string &path, const std::string &bytes)
{
    FILE *f = std::fopen(path.c_str(), "wb");
    TEST_ASSERT_NOT_NULL_MESSAGE(f, path.c_str());
    TEST_ASSERT_TRUE(std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size());
    TEST_ASSERT_EQUAL_INT(0, std::fclose(f));
}

// ---- running the program -----------------------------------------------------------

struct Run {
    int code;
    std::string out, err;
};

Run run(std::vector<std::string> args)
{
    std::string outp = tmp("run" + std::to_string(g_seq) + ".out"), errp = tmp("run" + std::to_string(g_seq) + ".err");
    g_seq++;
    std::vector<char *> argv;
    std::string prog = GS_PROGRAM;
    std::string cmd = "video";
    argv.push_back(&prog[0]);
    if (!(args.size() == 1 && args[0] == "--help-top")) argv.push_back(&cmd[0]);
    for (auto &a : args) argv.push_back(&a[0]);
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, outp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&fa, STDERR_FILENO, errp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid;
    int rc = posix_spawn(&pid, GS_PROGRAM, &fa, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, rc, "posix_spawn " GS_PROGRAM);
    int status;
    TEST_ASSERT_EQUAL_INT(pid, waitpid(pid, &status, 0));
    Run r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.out = slurp(outp);
    r.err = slurp(errp);
    return r;
}

std::string str(const std::string &line, const char *key)
{
    std::string pat = std::string("\"") + key + "\":\"";
    size_t k = line.find(pat);
    if (k == std::string::npos) return "";
    size_t e = line.find('"', k + pat.size());
    return line.substr(k + pat.size(), e - k - pat.size());
}

int count_lines(const std::string &s)
{
    int n = 0;
    for (char c : s) n += c == '\n';
    return n;
}

// The flights with the true q and diameter (2 %), the summary within 2 %. The
// detector may learn the ball's colour during the first flight and see only
// its end: that flight may be missing or rejected, every other one must be
// found, accepted and right.
void check_ball_run(const Run &r, const Scene &s, double tol_rel)
{
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, r.code, r.err.c_str());
    auto jumps = lines_of(r.out, "jump");
    int accepted = 0;
    const double first_end = s.empty_s + s.rest_s + s.flight_s;
    for (const auto &j : jumps) {
        if (j.find("\"accepted\":true") == std::string::npos) {
            TEST_ASSERT_TRUE_MESSAGE(num(j, "t_land_s") < first_end + 0.1, j.c_str());
            continue;
        }
        accepted++;
        TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(tol_rel * s.q_m_per_px, s.q_m_per_px, num(j, "q_m_per_px"), j.c_str());
        TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(tol_rel * a_px(s), a_px(s), num(j, "a_px_s2"), j.c_str());
        TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.02 * s.diameter_m, s.diameter_m, num(j, "height_m"), j.c_str());
        if (num(j, "t_takeoff_s") > first_end)
            TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.05 * s.flight_s, s.flight_s, num(j, "flight_time_s"), j.c_str());
    }
    TEST_ASSERT_TRUE_MESSAGE(static_cast<int>(jumps.size()) <= s.n_throws, r.out.c_str());
    TEST_ASSERT_TRUE_MESSAGE(accepted >= s.n_throws - 1, r.out.c_str());
    auto sum = lines_of(r.out, "summary");
    TEST_ASSERT_EQUAL_INT(1, static_cast<int>(sum.size()));
    TEST_ASSERT_EQUAL_INT(0, static_cast<int>(num(sum[0], "track")));
    TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.02 * s.diameter_m, s.diameter_m, num(sum[0], "height_m"), sum[0].c_str());
    TEST_ASSERT_EQUAL_INT(accepted, static_cast<int>(num(sum[0], "n_jumps")));
    std::printf("  %d of %d flights accepted; diameter %.4f m (truth %.4f, %+.2f %%)\n", accepted, s.n_throws,
                num(sum[0], "height_m"), s.diameter_m, 100.0 * (num(sum[0], "height_m") / s.diameter_m - 1.0));
}

// stderr holds exactly one line, "gravscale: <path>: ..."
void check_one_error_line(const Run &r, const std::string &path)
{
    TEST_ASSERT_EQUAL_INT_MESSAGE(1, count_lines(r.err), r.err.c_str());
    TEST_ASSERT_EQUAL_STRING_LEN_MESSAGE(("gravscale: " + path + ":").c_str(), r.err.c_str(),
                                         path.size() + 12, r.err.c_str());
}

std::string g_ffv1;  // the FFV1 clip of the default scene, shared by several tests

}  // namespace

// ---- tests -----------------------------------------------------------------------------

static void test_ffv1_ball_size_and_scale(void)
{
    Scene s;
    Run r = run({g_ffv1, "--detector", "ball"});
    check_ball_run(r, s, 0.02);
    auto start = lines_of(r.out, "start");
    TEST_ASSERT_EQUAL_INT(1, static_cast<int>(start.size()));
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, static_cast<int>(r.out.find("{\"event\":\"start\"")), "start comes first");
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 60.0, num(start[0], "fps_source"));
    TEST_ASSERT_EQUAL_STRING("container", str(start[0], "fps_origin").c_str());
    TEST_ASSERT_EQUAL_STRING("point", str(start[0], "layout").c_str());
}

static void test_mjpg_ball_size_and_scale(void)
{
    Scene s;
    s.q_m_per_px = 0.003;
    s.diameter_m = 0.06;  // 20 px
    s.flight_s = 0.65;
    std::string p = tmp("mjpg.avi");
    TEST_ASSERT_TRUE(write_clip(p, "MJPG", s));
    check_ball_run(run({p}), s, 0.02);
}

static void test_nmea_output(void)
{
    Run r = run({g_ffv1, "--output-format", "nmea"});
    TEST_ASSERT_EQUAL_INT(0, r.code);
    TEST_ASSERT_EQUAL_INT(0, static_cast<int>(r.out.find("$GSSTA,")));
    TEST_ASSERT_TRUE_MESSAGE(r.out.find("$GSSUM,0.08") != std::string::npos || r.out.find("$GSSUM,0.07") != std::string::npos,
                             r.out.c_str());
}

static void test_frame_source_ffv1_times_exact(void)
{
    std::string err;
    gs::FrameSource::Error kind;
    auto src = gs::FrameSource::open(g_ffv1, gs::FrameSourceOptions(), err, kind);
    TEST_ASSERT_NOT_NULL_MESSAGE(src.get(), err.c_str());
    TEST_ASSERT_EQUAL_INT(640, src->size().width);
    gs::Frame f;
    int n = 0;
    while (src->next(f)) {
        TEST_ASSERT_EQUAL_INT(n, static_cast<int>(f.index));
        TEST_ASSERT_DOUBLE_WITHIN(1e-6, n / 60.0, f.t_s);
        TEST_ASSERT_FALSE(f.t_repaired);
        n++;
    }
    TEST_ASSERT_EQUAL_INT(scene_frames(Scene()), n);
    TEST_ASSERT_EQUAL_INT(n, static_cast<int>(src->frames_announced()));
}

// H.264 with B-frames: Debian's OpenCV 4.6 reports 0 ms for the frames drained at the end.
static void test_h264_drained_frames_get_increasing_times(void)
{
    Scene s;
    s.n_throws = 1;
    std::string p = tmp("h264.mp4");
    if (!write_clip(p, "avc1", s)) TEST_IGNORE_MESSAGE("this FFmpeg cannot write H.264");
    std::string err;
    gs::FrameSource::Error kind;
    auto src = gs::FrameSource::open(p, gs::FrameSourceOptions(), err, kind);
    TEST_ASSERT_NOT_NULL_MESSAGE(src.get(), err.c_str());
    gs::Frame f;
    int n = 0;
    while (src->next(f)) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-3, n / 60.0, f.t_s);
        n++;
    }
    TEST_ASSERT_EQUAL_INT(scene_frames(s), n);
    std::printf("h264: %lld of %d frame times repaired\n", static_cast<long long>(src->times_repaired()), n);
    TEST_ASSERT_TRUE(src->times_repaired() < 8);
    check_ball_run(run({p}), s, 0.02);
}

// A textured H.264 clip (B-frames, every pixel's colour moving) of the given width.
static bool write_textured_h264(const std::string &path, int width, int height, int frames)
{
    cv::VideoWriter w(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('a', 'v', 'c', '1'), 30.0,
                      cv::Size(width, height), true);
    if (!w.isOpened()) return false;
    cv::Mat base(height, width, CV_8UC3);
    cv::RNG rng(7);
    rng.fill(base, cv::RNG::UNIFORM, 0, 256);
    cv::GaussianBlur(base, base, cv::Size(0, 0), 2.0);
    for (int i = 0; i < frames; i++) {
        cv::Mat f;
        cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 1.5 * i, 0, 1, 0.5 * i);
        cv::warpAffine(base, f, shift, base.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
        cv::circle(f, cv::Point(width / 4 + 3 * i, height / 2), height / 6, cv::Scalar(30, 140, 250), -1);
        w.write(f);
    }
    w.release();
    return true;
}

// Every frame and time of cv::VideoCapture: the same pixels, the same stream times
// (repaired where OpenCV's do not increase), the same number of frames, whichever
// decoder the frame source took and with any number of decoding threads.
static void check_same_as_opencv(const std::string &path, int threads, const char *decoder)
{
    gs::FrameSourceOptions fo;
    fo.decode_threads = threads;
    std::string err;
    gs::FrameSource::Error kind;
    auto src = gs::FrameSource::open(path, fo, err, kind);
    TEST_ASSERT_NOT_NULL_MESSAGE(src.get(), err.c_str());
    TEST_ASSERT_EQUAL_STRING(decoder, src->decoder());
    cv::VideoCapture cap(path, cv::CAP_FFMPEG);
    TEST_ASSERT_TRUE(cap.isOpened());
    gs::Frame f;
    cv::Mat ref;
    int n = 0, repaired = 0;
    double last_ms = -1e300;
    while (src->next(f)) {
        TEST_ASSERT_TRUE_MESSAGE(cap.read(ref) && !ref.empty(), "the frame source gave more frames than OpenCV");
        double ms = cap.get(cv::CAP_PROP_POS_MSEC);
        TEST_ASSERT_EQUAL_INT(ref.rows, f.bgr.rows);
        TEST_ASSERT_EQUAL_INT(ref.cols, f.bgr.cols);
        TEST_ASSERT_EQUAL_INT_MESSAGE(0, cv::norm(ref, f.bgr, cv::NORM_INF), "a pixel differs from OpenCV's");
        if (n == 0 || ms * 1e-3 > last_ms * 1e-3) {
            TEST_ASSERT_FALSE(f.t_repaired);
            TEST_ASSERT_EQUAL_DOUBLE(ms * 1e-3, f.t_stream_s);
        } else {
            TEST_ASSERT_TRUE(f.t_repaired);
            repaired++;
        }
        if (!f.t_repaired) last_ms = ms;
        n++;
    }
    TEST_ASSERT_FALSE_MESSAGE(cap.read(ref), "OpenCV gave more frames than the frame source");
    TEST_ASSERT_TRUE(n > 0);
    TEST_ASSERT_EQUAL_INT(repaired, static_cast<int>(src->times_repaired()));
}

static void test_frame_source_same_as_opencv(void)
{
    std::string direct = tmp("textured_640.mp4"), odd = tmp("textured_324.mp4");
    if (!write_textured_h264(direct, 640, 360, 40) || !write_textured_h264(odd, 324, 240, 20))
        TEST_IGNORE_MESSAGE("this FFmpeg cannot write H.264");
    check_same_as_opencv(direct, 1, "libavcodec");
    check_same_as_opencv(direct, 0, "libavcodec");
    check_same_as_opencv(odd, 1, "opencv");  // a width of 8-pixel blocks and a half: OpenCV's own path
    check_same_as_opencv(g_ffv1, 0, "opencv");  // not 4:2:0
}

static Scene slowmo_scene(void)
{
    Scene s;
    s.q_m_per_px = 0.002;
    s.diameter_m = 0.06;  // 30 px, a tennis ball
    s.true_fps = 120.0;
    s.stored_fps = 30.0;  // a phone's slow motion: 120 fps capture stored as 30 fps
    s.flight_s = 0.3;
    s.n_throws = 3;
    s.drift_px_s = 150.0;
    return s;
}

static std::string slowmo_config(void)
{
    // A wide size range so that the 16x wrong rate still gives flights to look
    // at; the colour is given because learning it needs a plausible free fall,
    // which the wrong rate is not.
    std::string p = tmp("slowmo.cfg");
    write_bytes(p, "[core]\nsize_min_m = 0.02\nsize_max_m = 2.0\n[ball]\ncolor = fixed\nhue_deg = 30\n");
    return p;
}

static void test_false_frame_rate_cli(void)
{
    Scene s = slowmo_scene();
    std::string p = tmp("slowmo.avi"), cfg = slowmo_config();
    TEST_ASSERT_TRUE(write_clip(p, "FFV1", s));

    Run right = run({p, "--fps", "120", "--config", cfg});
    check_ball_run(right, s, 0.02);
    auto st = lines_of(right.out, "start");
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 120.0, num(st[0], "fps_source"));
    TEST_ASSERT_EQUAL_STRING("cli", str(st[0], "fps_origin").c_str());

    Run wrong = run({p, "--config", cfg});
    TEST_ASSERT_EQUAL_INT(0, wrong.code);
    st = lines_of(wrong.out, "start");
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 30.0, num(st[0], "fps_source"));
    TEST_ASSERT_EQUAL_STRING("container", str(st[0], "fps_origin").c_str());
    auto jumps = lines_of(wrong.out, "jump");
    TEST_ASSERT_TRUE_MESSAGE(!jumps.empty(), wrong.out.c_str());
    for (const auto &j : jumps) {
        // 4x slower time: a_px 16x too small, the size 16x too large
        double ratio = a_px(s) / num(j, "a_px_s2");
        TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(0.03 * 16, 16.0, ratio, j.c_str());
    }
}

static void test_false_frame_rate_metadata(void)
{
    Scene s = slowmo_scene();
    std::string p = tmp("slowmo_src.avi"), tagged = tmp("slowmo_tagged.mp4"), cfg = slowmo_config();
    TEST_ASSERT_TRUE(write_clip(p, "MJPG", s));
    TEST_ASSERT_TRUE_MESSAGE(remux_with_capture_fps(p, tagged, "120.000000"), "remux with the capture-fps tag");

    gs::StreamProbe pr;
    std::string err;
    TEST_ASSERT_TRUE_MESSAGE(gs::probe_video(tagged, pr, err), err.c_str());
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 120.0, pr.capture_fps);
    TEST_ASSERT_DOUBLE_WITHIN(0.01, 30.0, pr.avg_fps);

    Run r = run({tagged, "--config", cfg});
    check_ball_run(r, s, 0.02);
    auto st = lines_of(r.out, "start");
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 120.0, num(st[0], "fps_source"));
    TEST_ASSERT_EQUAL_STRING("metadata", str(st[0], "fps_origin").c_str());

    // --fps wins over the tag
    Run c = run({tagged, "--config", cfg, "--fps", "30"});
    st = lines_of(c.out, "start");
    TEST_ASSERT_EQUAL_STRING("cli", str(st[0], "fps_origin").c_str());
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 30.0, num(st[0], "fps_source"));
}

static void test_image_sequence(void)
{
    Scene s;
    s.n_throws = 2;
    std::string dir = tmp("seq");
    TEST_ASSERT_EQUAL_INT(0, mkdir(dir.c_str(), 0755));
    int n = scene_frames(s);
    for (int i = 0; i < n; i++) {
        bool more;
        char name[64];
        std::snprintf(name, sizeof name, "/f%d.png", i);  // unpadded: needs numeric order
        TEST_ASSERT_TRUE(cv::imwrite(dir + name, render_frame(s, i / s.true_fps, &more)));
    }
    Run r = run({dir, "--fps", "60"});
    check_ball_run(r, s, 0.02);
    TEST_ASSERT_EQUAL_STRING("cli", str(lines_of(r.out, "start")[0], "fps_origin").c_str());

    Run nofps = run({dir});
    TEST_ASSERT_EQUAL_INT(2, nofps.code);
    check_one_error_line(nofps, dir);

    Run pat = run({dir + "/f%d.png", "--fps", "60"});
    check_ball_run(pat, s, 0.02);

    // a damaged image inside the sequence: bad input, exit 1, no summary
    write_bytes(dir + "/f5.png", "not a png");
    Run bad = run({dir, "--fps", "60"});
    TEST_ASSERT_EQUAL_INT(1, bad.code);
    TEST_ASSERT_EQUAL_INT(1, count_lines(bad.err));
    TEST_ASSERT_TRUE(bad.err.find("f5.png") != std::string::npos);
    TEST_ASSERT_TRUE(lines_of(bad.out, "summary").empty());
}

static void test_bad_files(void)
{
    std::string missing = tmp("no_such_clip.mp4");
    Run r = run({missing});
    TEST_ASSERT_EQUAL_INT(1, r.code);
    check_one_error_line(r, missing);
    TEST_ASSERT_TRUE(r.err.find("no such file") != std::string::npos);
    TEST_ASSERT_EQUAL_INT(0, static_cast<int>(r.out.size()));

    std::string empty = tmp("empty.mp4");
    write_bytes(empty, "");
    r = run({empty});
    TEST_ASSERT_EQUAL_INT(1, r.code);
    check_one_error_line(r, empty);

    std::string junk = tmp("junk.avi");
    std::string bytes;
    uint32_t x = 2463534242u;
    for (int i = 0; i < 100000; i++) {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        bytes.push_back(static_cast<char>(x & 0xff));
    }
    write_bytes(junk, bytes);
    r = run({junk});
    TEST_ASSERT_EQUAL_INT(1, r.code);
    check_one_error_line(r, junk);

    // a text file that happens to be named .mp4
    std::string text = tmp("text.mp4");
    write_bytes(text, "t,x,y,c\n0,1,2,1\n");
    r = run({text});
    TEST_ASSERT_EQUAL_INT(1, r.code);
    check_one_error_line(r, text);

    // a truncated clip: what decodes is used, never a crash
    std::string whole = slurp(g_ffv1), cut = tmp("truncated.avi");
    write_bytes(cut, whole.substr(0, whole.size() / 2));
    r = run({cut});
    TEST_ASSERT_TRUE_MESSAGE(r.code == 0 || r.code == 1, r.err.c_str());
    if (r.code == 0) TEST_ASSERT_EQUAL_INT(1, static_cast<int>(lines_of(r.out, "summary").size()));
    else check_one_error_line(r, cut);

    // usage errors
    TEST_ASSERT_EQUAL_INT(2, run({g_ffv1, "--detector", "person"}).code);
    TEST_ASSERT_EQUAL_INT(2, run({g_ffv1, "--fps", "-3"}).code);
    TEST_ASSERT_EQUAL_INT(2, run({}).code);
    TEST_ASSERT_EQUAL_INT(2, run({g_ffv1, "--bogus"}).code);
    std::string badcfg = tmp("bad.cfg");
    write_bytes(badcfg, "[core]\nsize_min_m = banana\n");
    r = run({g_ffv1, "--config", badcfg});
    TEST_ASSERT_EQUAL_INT(2, r.code);
    check_one_error_line(r, badcfg);
    Run h = run({"--help"});
    TEST_ASSERT_EQUAL_INT(0, h.code);
    TEST_ASSERT_TRUE(h.out.find("--overlay") != std::string::npos);
}

static void test_no_ball_gives_null_summary(void)
{
    Scene s;
    s.ball = false;
    s.n_throws = 1;
    std::string p = tmp("noball.avi");
    TEST_ASSERT_TRUE(write_clip(p, "FFV1", s));
    Run r = run({p});
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, r.code, r.err.c_str());
    TEST_ASSERT_EQUAL_INT(0, static_cast<int>(lines_of(r.out, "jump").size()));
    auto sum = lines_of(r.out, "summary");
    TEST_ASSERT_EQUAL_INT(1, static_cast<int>(sum.size()));
    TEST_ASSERT_TRUE_MESSAGE(sum[0].find("\"height_m\":null") != std::string::npos, sum[0].c_str());
    TEST_ASSERT_EQUAL_INT(0, static_cast<int>(num(sum[0], "track")));
}

static void test_overlay_video_sheet_and_plot(void)
{
    Scene s;
    std::string ov = tmp("overlay.avi"), sheet = tmp("sheet.png"), plot = tmp("plot.png"), trace = tmp("trace.jsonl");
    Run r = run({g_ffv1, "--overlay", ov, "--plot", plot, "--trace", trace});
    check_ball_run(r, s, 0.02);
    // the trace has the samples; stdout has none
    std::string t = slurp(trace);
    TEST_ASSERT_TRUE(lines_of(t, "sample").size() > 100);
    TEST_ASSERT_TRUE(lines_of(r.out, "sample").empty());

    cv::VideoCapture cap(ov);
    TEST_ASSERT_TRUE(cap.isOpened());
    cv::Mat src_frame, drawn;
    cv::VideoCapture orig(g_ffv1);
    int n = 0, differ = 0;
    while (cap.read(drawn)) {
        TEST_ASSERT_TRUE(orig.read(src_frame));
        TEST_ASSERT_EQUAL_INT(s.width, drawn.cols);
        cv::Mat d;
        cv::absdiff(drawn, src_frame, d);
        if (cv::norm(d, cv::NORM_INF) > 100) differ++;
        n++;
    }
    TEST_ASSERT_EQUAL_INT(scene_frames(s), n);
    TEST_ASSERT_EQUAL_INT_MESSAGE(n, differ, "every frame carries drawings");

    cv::Mat p = cv::imread(plot);
    TEST_ASSERT_EQUAL_INT(1400, p.cols);
    TEST_ASSERT_EQUAL_INT(940, p.rows);

    r = run({g_ffv1, "--overlay", sheet});
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, r.code, r.err.c_str());
    cv::Mat sh = cv::imread(sheet);
    TEST_ASSERT_FALSE(sh.empty());
    // take-off, apex and landing of each flight: tiles of 640x480 with 4 px gaps, 2-3 columns
    int jumps = static_cast<int>(lines_of(r.out, "jump").size());
    int cols = jumps * 3 <= 4 ? jumps * 3 : (jumps * 3 <= 9 ? 3 : 4);
    TEST_ASSERT_TRUE(jumps >= 2);
    TEST_ASSERT_EQUAL_INT(cols * 644 + 4, sh.cols);
    TEST_ASSERT_EQUAL_INT(((jumps * 3 + cols - 1) / cols) * 484 + 4, sh.rows);

    r = run({g_ffv1, "--overlay", tmp("overlay.xyz")});
    TEST_ASSERT_EQUAL_INT(3, r.code);
    r = run({g_ffv1, "--plot", g_dir + "/no/such/dir/plot.png"});
    TEST_ASSERT_EQUAL_INT(3, r.code);
}

int main(void)
{
    char templ[] = "/tmp/gs_test_video_XXXXXX";
    if (!mkdtemp(templ)) {
        std::perror("mkdtemp");
        return 1;
    }
    g_dir = templ;
    g_ffv1 = tmp("ball_ffv1.avi");
    if (!write_clip(g_ffv1, "FFV1", Scene())) {
        std::fprintf(stderr, "cannot write an FFV1 clip\n");
        return 1;
    }
    UNITY_BEGIN();
    RUN_TEST(test_ffv1_ball_size_and_scale);
    RUN_TEST(test_mjpg_ball_size_and_scale);
    RUN_TEST(test_nmea_output);
    RUN_TEST(test_frame_source_ffv1_times_exact);
    RUN_TEST(test_h264_drained_frames_get_increasing_times);
    RUN_TEST(test_frame_source_same_as_opencv);
    RUN_TEST(test_false_frame_rate_cli);
    RUN_TEST(test_false_frame_rate_metadata);
    RUN_TEST(test_image_sequence);
    RUN_TEST(test_bad_files);
    RUN_TEST(test_no_ball_gives_null_summary);
    RUN_TEST(test_overlay_video_sheet_and_plot);
    int fails = UNITY_END();
    if (fails == 0) {
        std::string cmd = "rm -rf '" + g_dir + "'";
        if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "could not remove %s\n", g_dir.c_str());
    }
    return fails;
}
