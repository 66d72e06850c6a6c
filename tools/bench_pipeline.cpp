// bench_pipeline.cpp - throughput of the whole person pipeline as shipped:
// runs the real `gravscale video FILE --detector pose` (decode -> pose networks
// -> camera motion and scene facts -> COM -> core -> emit) on 720p and 1080p
// clips, pinned to one CPU or to two, sequential (--prefetch 0) and with the
// decode and network threads (--prefetch 2), and prints frames/s, CPU time per
// frame and where the time went (the program's own stage clocks, written to
// GS_VIDEO_TIMES by cmd_video.cpp).
//
//   bench_pipeline [CLIP] [--program PATH] [--models DIR] [--model lite|full|heavy|all|lite,full]
//                  [--res 720|1080|both] [--cpus 1|2|both] [--prefetch 0|2|both]
//                  [--threads auto|1|2|auto,1] [--frames N] [--repeat N] [--wait-idle S]
//
// CLIP defaults to $GS_SHARED_DIR (else ../shared) /data/real/jumpvision_jumps/
// cmj_gym_handheld_30fps.mp4 (720 x 1280, 54 frames). Its frames are played
// forwards and backwards until --frames (default 540, 18 s at 30 fps) and
// written as H.264 (OpenCV's FFmpeg writer; MJPG if it cannot) at 720 x 1280
// and scaled to 1080 x 1920, into a temporary folder: long enough that the
// one-off start (loading the networks, about 0.15 s) does not count much, and
// decoded by the program as any clip. "fps" is the frame loop's (frames /
// loop time); "e2e" counts the whole process from exec to exit. CPU ms per
// frame is the process's (all threads, children's rusage) over all frames
// and does not depend on the other load of the machine; wall times do: the
// load average (1 min) is printed before and after each row, and "others":
// how many CPUs the machine's other processes kept busy during the run
// (/proc/stat's busy time less this run's CPU time, over its wall time; 0 on
// an idle machine, 2 when they took both CPUs of this one). --wait-idle S
// waits before each run, up to S seconds, for a second in which the others
// use less than a quarter of a CPU. Each row is the
// best (highest fps) of --repeat runs (default 1). The outputs of the
// sequential and the prefetching runs of one clip and model are compared
// byte for byte ("same").
//
// Stage columns, ms per frame of wall time spent in each: decode (FFmpeg via
// OpenCV), pose (the networks and the tracker), net (the pose networks with
// their crop and blob, summed: a census runs the detector in a thread of its
// own beside the landmark network, so net can exceed pose), scene (camera
// motion on background corners, stabilised keypoints, scene facts), core
// (COM, core pipeline and emitting the events). "net %" is pose over the
// loop's wall time: the pose stage's share of the sequential pipeline, or how
// busy the network thread is with prefetch (near 100 %: it is what limits the
// frame rate).
#include <sched.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bench_args.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

namespace {

double now_s()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double load1()
{
    double l = NAN;
    if (FILE *f = std::fopen("/proc/loadavg", "r")) {
        if (std::fscanf(f, "%lf", &l) != 1) l = NAN;
        std::fclose(f);
    }
    return l;
}

// CPU time the whole machine spent busy, all processes (containers included), s
double machine_busy_s()
{
    unsigned long long v[8] = {0};
    FILE *f = std::fopen("/proc/stat", "r");
    if (!f) return NAN;
    int n = std::fscanf(f, "cpu %llu %llu %llu %llu %llu %llu %llu %llu", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5],
                        &v[6], &v[7]);
    std::fclose(f);
    if (n != 8) return NAN;
    // user nice system idle iowait irq softirq steal: all but idle and iowait
    return static_cast<double>(v[0] + v[1] + v[2] + v[5] + v[6] + v[7]) / sysconf(_SC_CLK_TCK);
}

// Waits (up to max_s) for one second in which the other processes use less
// than a quarter of a CPU; returns the CPUs they used in the last second.
double wait_idle(double max_s)
{
    double t0 = now_s(), used = NAN;
    do {
        double b0 = machine_busy_s(), w0 = now_s();
        usleep(1000000);
        used = (machine_busy_s() - b0) / (now_s() - w0);
    } while (!(used < 0.25) && now_s() - t0 < max_s);
    return used;
}

std::string self_dir()
{
    char buf[4096];
    ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
    if (n <= 0) return ".";
    buf[n] = '\0';
    std::string s(buf);
    size_t k = s.find_last_of('/');
    return k == std::string::npos ? "." : s.substr(0, k);
}

// a number after "key": in a JSON line (NaN if absent)
double jnum(const std::string &line, const std::string &key)
{
    std::string pat = "\"" + key + "\":";
    size_t k = line.find(pat);
    if (k == std::string::npos) return NAN;
    return std::strtod(line.c_str() + k + pat.size(), nullptr);
}

std::string read_all(const std::string &path)
{
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

bool write_clip(const std::vector<cv::Mat> &frames, double scale, int n_frames, double fps, const std::string &dir,
                const std::string &name, std::string &path)
{
    cv::Size sz(static_cast<int>(std::lround(frames[0].cols * scale)), static_cast<int>(std::lround(frames[0].rows * scale)));
    for (int attempt = 0; attempt < 2; attempt++) {
        path = dir + "/" + name + (attempt == 0 ? ".mp4" : ".avi");
        int fcc = attempt == 0 ? cv::VideoWriter::fourcc('a', 'v', 'c', '1') : cv::VideoWriter::fourcc('M', 'J', 'P', 'G');
        cv::VideoWriter w(path, cv::CAP_FFMPEG, fcc, fps, sz, true);
        if (!w.isOpened()) continue;
        const int n = static_cast<int>(frames.size()), period = n > 1 ? 2 * n - 2 : 1;
        cv::Mat r;
        for (int i = 0; i < n_frames; i++) {
            int k = i % period;
            if (k >= n) k = period - k;  // backwards: no jump in the picture where the loop turns
            if (std::fabs(scale - 1.0) < 1e-9) w.write(frames[k]);
            else {
                cv::resize(frames[k], r, sz, 0, 0, cv::INTER_LINEAR);
                w.write(r);
            }
        }
        return true;
    }
    return false;
}

struct RunResult {
    bool ok = false;
    double wall_s = 0, cpu_s = 0, load_before = NAN, load_after = NAN;
    double others = NAN;  // CPUs the other processes of the machine used during the run
    std::string times;  // the GS_VIDEO_TIMES line
    std::string out;    // stdout
};

RunResult run_once(const std::string &program, const std::vector<std::string> &args, int cpus,
                   const std::string &tmp)
{
    RunResult r;
    std::string times_path = tmp + "/times.jsonl", out_path = tmp + "/out.jsonl", err_path = tmp + "/err.txt";
    std::remove(times_path.c_str());
    r.load_before = load1();
    double busy0 = machine_busy_s();
    double t0 = now_s();
    pid_t pid = fork();
    if (pid < 0) return r;
    if (pid == 0) {
        cpu_set_t set;
        CPU_ZERO(&set);
        for (int c = 0; c < cpus; c++) CPU_SET(c, &set);
        if (sched_setaffinity(0, sizeof set, &set) != 0) _exit(126);
        setenv("GS_VIDEO_TIMES", times_path.c_str(), 1);
        int fo = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        int fe = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fo < 0 || fe < 0) _exit(126);
        dup2(fo, 1);
        dup2(fe, 2);
        std::vector<char *> av;
        av.push_back(const_cast<char *>(program.c_str()));
        for (const std::string &a : args) av.push_back(const_cast<char *>(a.c_str()));
        av.push_back(nullptr);
        execv(program.c_str(), av.data());
        _exit(127);
    }
    int st = 0;
    rusage ru;
    if (wait4(pid, &st, 0, &ru) != pid) return r;
    r.wall_s = now_s() - t0;
    r.cpu_s = ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
    r.load_after = load1();
    r.others = std::max(0.0, (machine_busy_s() - busy0 - r.cpu_s) / r.wall_s);
    r.ok = WIFEXITED(st) && WEXITSTATUS(st) == 0;
    if (!r.ok) std::fprintf(stderr, "bench_pipeline: the program failed (status %d): %s\n", st, read_all(err_path).c_str());
    r.times = read_all(times_path);
    r.out = read_all(out_path);
    return r;
}

int usage()
{
    std::fprintf(stderr,
                 "usage: bench_pipeline [CLIP] [--program PATH] [--models DIR] [--model lite|full|heavy|all|lite,full]\n"
                 "                      [--res 720|1080|both] [--cpus 1|2|both] [--prefetch 0|2|both]\n"
                 "                      [--threads auto|1|2|auto,1] [--frames N] [--repeat N] [--wait-idle S]\n");
    return 2;
}

}  // namespace

int main(int argc, char **argv)
{
    std::string clip = gs_bench::gym_clip();
    std::string program = self_dir() + "/gravscale", models_dir, model_arg = "lite", res_arg = "both",
                cpus_arg = "both", prefetch_arg = "both", threads_arg = "auto", frames_arg = "540",
                repeat_arg = "1", wait_arg = "0";
    if (!gs_bench::parse_options(argc, argv,
                                 {{"--program", &program}, {"--models", &models_dir}, {"--model", &model_arg},
                                  {"--res", &res_arg}, {"--cpus", &cpus_arg}, {"--prefetch", &prefetch_arg},
                                  {"--threads", &threads_arg}, {"--frames", &frames_arg}, {"--repeat", &repeat_arg},
                                  {"--wait-idle", &wait_arg}},
                                 &clip))
        return usage();
    int n_frames = 0, repeat = 0;
    double idle_wait_s = 0;
    std::vector<std::string> models, threads;  // OpenCV threads: auto (OpenCV's default: the CPUs allowed), 1, 2
    std::vector<int> heights, cpus, prefetch;
    if (!gs_bench::to_int(frames_arg, 1, n_frames) || !gs_bench::to_int(repeat_arg, 1, repeat) ||
        !gs_bench::to_seconds(wait_arg, idle_wait_s) ||
        !gs_bench::pick(model_arg, "all", {"lite", "full", "heavy"}, models) ||
        !gs_bench::pick_ints(res_arg, "both", {"720", "1080"}, heights) ||
        !gs_bench::pick_ints(cpus_arg, "both", {"1", "2"}, cpus) ||
        !gs_bench::pick_ints(prefetch_arg, "both", {"0", "2"}, prefetch) ||
        !gs_bench::pick(threads_arg, "both", {"auto", "1", "2"}, threads))
        return usage();
    if (access(program.c_str(), X_OK) != 0) {
        std::fprintf(stderr, "bench_pipeline: %s: not a program (--program PATH)\n", program.c_str());
        return 1;
    }

    cv::VideoCapture cap(clip);
    std::vector<cv::Mat> frames;
    cv::Mat f;
    while (cap.isOpened() && cap.read(f)) frames.push_back(f.clone());
    if (frames.empty()) {
        std::fprintf(stderr, "bench_pipeline: %s: no frames\n", clip.c_str());
        return 1;
    }
    double fps = cap.get(cv::CAP_PROP_FPS);
    if (!(fps > 0)) fps = 30.0;
    char templ[] = "/tmp/gs_bench_pipeline_XXXXXX";
    if (!mkdtemp(templ)) return 1;
    const std::string dir = templ;

    std::printf("clip %s: %zu frames %dx%d, played forwards and backwards to %d frames; program %s\n", clip.c_str(),
                frames.size(), frames[0].cols, frames[0].rows, n_frames, program.c_str());
    std::printf("%-5s %9s %4s %3s %3s | %6s %6s %7s | %6s %6s %6s %6s %6s | %5s | %-11s %s\n", "model", "frame", "cpus",
                "thr", "pre", "fps", "e2e", "cpu ms", "decode", "pose", "net", "scene", "core", "net%", "load  others", "output");
    int rc = 0;
    for (int h : heights) {
        double scale = static_cast<double>(h) / std::min(frames[0].cols, frames[0].rows);
        std::string path;
        double t0 = now_s();
        if (!write_clip(frames, scale, n_frames, fps, dir, "clip" + std::to_string(h), path)) {
            std::fprintf(stderr, "bench_pipeline: cannot write a clip\n");
            return 1;
        }
        std::printf("# %dp clip written in %.1f s: %s\n", h, now_s() - t0, path.c_str());
        std::fflush(stdout);
        for (const std::string &m : models) {
            for (int c : cpus)
            for (const std::string &thr : threads) {
                if (c == 1 && thr == "1" && threads.size() > 1) continue;  // auto is 1 on one CPU
                std::string seq_out;
                for (int pf : prefetch) {
                    std::vector<std::string> args = {"video", path, "--detector", "pose", "--model", m,
                                                     "--prefetch", std::to_string(pf)};
                    if (!models_dir.empty()) args.insert(args.end(), {"--models", models_dir});
                    if (thr != "auto") args.insert(args.end(), {"--threads", thr});
                    RunResult best;
                    double best_fps = -1;
                    for (int k = 0; k < repeat; k++) {
                        if (idle_wait_s > 0) wait_idle(idle_wait_s);
                        RunResult r = run_once(program, args, c, dir);
                        if (!r.ok) {
                            rc = 1;
                            continue;
                        }
                        double loop = jnum(r.times, "loop_s"), n = jnum(r.times, "frames");
                        if (n / loop > best_fps) {
                            best_fps = n / loop;
                            best = r;
                        }
                    }
                    if (!best.ok) continue;
                    const std::string &t = best.times;
                    double n = jnum(t, "frames"), loop = jnum(t, "loop_s");
                    double net = jnum(t, "network_ms");
                    const char *same = "";
                    if (pf == 0) seq_out = best.out;
                    else if (!seq_out.empty()) same = seq_out == best.out ? "same" : "DIFFERS";
                    if (!seq_out.empty() && pf != 0 && seq_out != best.out) rc = 1;
                    char res[32];
                    std::snprintf(res, sizeof res, "%dx%d", static_cast<int>(std::lround(frames[0].cols * scale)),
                                  static_cast<int>(std::lround(frames[0].rows * scale)));
                    std::printf("%-5s %9s %4d %3d %3d | %6.1f %6.1f %7.1f | %6.2f %6.1f %6.1f %6.1f %6.2f | %4.0f%% | %4.2f %4.2f %4.2f  %s\n",
                                m.c_str(), res, c, static_cast<int>(jnum(t, "cv_threads")), pf, n / loop, n / best.wall_s,
                                1e3 * best.cpu_s / n, jnum(t, "decode_ms"), jnum(t, "pose_ms"), net, jnum(t, "scene_ms"),
                                jnum(t, "core_ms"), 100.0 * jnum(t, "pose_ms") * n / (1e3 * loop), best.load_before, best.load_after, best.others, same);
                    std::fflush(stdout);
                }
            }
        }
        std::remove(path.c_str());
    }
    std::remove((dir + "/times.jsonl").c_str());
    std::remove((dir + "/out.jsonl").c_str());
    std::remove((dir + "/err.txt").c_str());
    rmdir(dir.c_str());
    return rc;
}
