// test_pose_prefetch.cpp - the prefetching frame loop of `gravscale video
// --detector pose` (decode and pose networks in their own threads, --prefetch
// N) gives exactly the output of the sequential loop (--prefetch 0), byte for
// byte, events and trace, on real clips: the gym jump (tracked throughout) and
// people walking (the detector runs again and again). And gs::Prefetch itself:
// order, the end, an exception from the worker, stopping early; gs::SideThread
// (the census's detector beside the landmarks): a job runs while its caller
// works, its exception comes back, the thread serves job after job.
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <sys/stat.h>
#include <sys/wait.h>
#include <thread>
#include <vector>

extern "C" {
#include "unity.h"
}

#include "pose_blazepose.hpp"
#include "prefetch.hpp"
#include "side_thread.hpp"
#include "gs_test_util.hpp"

#ifndef GS_SHARED_DIR
#error "GS_SHARED_DIR must be defined"
#endif

void setUp(void) {}
void tearDown(void) {}

namespace {

using gs_test::exists;

struct Run {
    int code = -1;
    std::string out, trace;
};

Run run(const std::string &clip, const std::string &args)
{
    const std::string trace = gs_test::tmp_path("gs_test_pose_prefetch.trace.jsonl");
    std::remove(trace.c_str());
    std::string cmd = std::string(GS_PROGRAM) + " video '" + clip + "' --detector pose --trace " + trace + " " + args;
    gs_test::Run sh = gs_test::run_shell(cmd, gs_test::tmp_path("gs_test_pose_prefetch.err"));
    Run r;
    r.code = sh.code;
    r.out = sh.out;
    r.trace = gs_test::slurp(trace);
    std::remove(trace.c_str());
    return r;
}

int count_of(const std::string &s, const std::string &pat)
{
    int n = 0;
    for (size_t p = s.find(pat); p != std::string::npos; p = s.find(pat, p + 1)) n++;
    return n;
}

// false (and the test ignored) when the clip or the networks are absent
bool have(const char *clip_rel, char *clip, size_t cap)
{
    std::snprintf(clip, cap, "%s/%s", GS_SHARED_DIR, clip_rel);
    std::string err;
    return exists(clip) && gs::pose_models_present(gs::PoseConfig(), err);
}

void same_output(const std::string &clip, const std::string &extra, const std::vector<int> &depths)
{
    Run seq = run(clip, "--prefetch 0 " + extra);
    TEST_ASSERT_EQUAL_INT(0, seq.code);
    TEST_ASSERT_TRUE(count_of(seq.out, "\"event\":\"summary\"") >= 1);
    TEST_ASSERT_TRUE(count_of(seq.trace, "\"event\":\"sample\"") > 10);
    for (int d : depths) {
        Run pre = run(clip, "--prefetch " + std::to_string(d) + " " + extra);
        TEST_ASSERT_EQUAL_INT(0, pre.code);
        TEST_ASSERT_TRUE_MESSAGE(pre.out == seq.out, ("events differ with --prefetch " + std::to_string(d)).c_str());
        TEST_ASSERT_TRUE_MESSAGE(pre.trace == seq.trace, ("trace differs with --prefetch " + std::to_string(d)).c_str());
    }
    std::printf("%s %s: %zu bytes of events, %zu of trace, the same with --prefetch 0 and", clip.c_str(),
                extra.c_str(), seq.out.size(), seq.trace.size());
    for (int d : depths) std::printf(" %d", d);
    std::printf("\n");
}

}  // namespace

static void test_prefetch_order_end_and_errors(void)
{
    for (size_t depth : {1u, 3u, 64u}) {
        int i = 0;
        gs::Prefetch<int> q([&](int &v) { return (v = i++) < 1000; }, depth);
        int v = -1, n = 0;
        while (q.next(v)) TEST_ASSERT_EQUAL_INT(n++, v);
        TEST_ASSERT_EQUAL_INT(1000, n);
        TEST_ASSERT_FALSE(q.next(v));  // stays at the end
    }
    {  // an exception in the worker: the items before it, then the exception
        int i = 0;
        gs::Prefetch<int> q(
            [&](int &v) {
                if (i == 5) throw std::runtime_error("boom");
                v = i++;
                return true;
            },
            2);
        int v = -1, n = 0;
        bool thrown = false;
        try {
            while (q.next(v)) TEST_ASSERT_EQUAL_INT(n++, v);
        } catch (const std::runtime_error &e) {
            thrown = std::strcmp(e.what(), "boom") == 0;
        }
        TEST_ASSERT_TRUE(thrown);
        TEST_ASSERT_EQUAL_INT(5, n);
    }
    {  // stopped early: the destructor joins a worker waiting on a full queue
        int i = 0;
        gs::Prefetch<int> q([&](int &v) { return (v = i++), true; }, 2);
        int v = -1;
        TEST_ASSERT_TRUE(q.next(v));
        TEST_ASSERT_EQUAL_INT(0, v);
    }
    {  // a chain, as the frame loop: stage 2 pulls from stage 1 in its worker
        int i = 0;
        gs::Prefetch<int> a([&](int &v) { return (v = i++) < 300; }, 2);
        gs::Prefetch<long> b(
            [&](long &w) {
                int v;
                if (!a.next(v)) return false;
                w = 3L * v;
                return true;
            },
            2);
        long w = -1, n = 0;
        while (b.next(w)) TEST_ASSERT_EQUAL_INT64(3 * n++, w);
        TEST_ASSERT_EQUAL_INT64(300, n);
    }
}

static void test_gym_jump_same_output_with_prefetch(void)
{
    // a plain buffer: TEST_IGNORE longjmps out of the test, past C++ destructors
    char clip[512];
    if (!have("data/real/jumpvision_jumps/cmj_gym_handheld_30fps.mp4", clip, sizeof clip))
        TEST_IGNORE_MESSAGE("jumpvision_jumps or the pose networks are absent");
    same_output(clip, "--model lite", {1, 2, 4});
    same_output(clip, "--model lite --threads 2", {2});
    same_output(clip, "--model full --threads 1", {2});
}

static void test_people_walking_same_output_with_prefetch(void)
{
    char clip[512];
    if (!have("data/real/opencv_vtest/vtest_first15s_h264.mp4", clip, sizeof clip))
        TEST_IGNORE_MESSAGE("opencv_vtest or the pose networks are absent");
    same_output(clip, "--model lite", {2});
}

// a side job runs on another thread while the caller goes on: the job waits for a
// flag only the caller sets (run in the caller's thread it would give up after 10 s)
void test_side_thread_runs_beside_its_caller(void)
{
    gs::SideThread side;
    for (int round = 0; round < 3; round++) {
        std::atomic<bool> caller_done(false), job_saw_it(false);
        std::thread::id job_thread;
        side.start([&] {
            job_thread = std::this_thread::get_id();
            const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
            while (!caller_done && std::chrono::steady_clock::now() < give_up) std::this_thread::yield();
            job_saw_it = caller_done.load();
        });
        caller_done = true;
        TEST_ASSERT_TRUE(side.finish() == nullptr);
        TEST_ASSERT_TRUE(job_saw_it);
        TEST_ASSERT_TRUE(job_thread != std::this_thread::get_id());
    }
    side.start([] { throw std::runtime_error("side job failed"); });
    std::exception_ptr e = side.finish();
    TEST_ASSERT_TRUE(e != nullptr);
    bool rethrown = false;
    try {
        std::rethrow_exception(e);
    } catch (const std::runtime_error &ex) {
        rethrown = std::strcmp(ex.what(), "side job failed") == 0;
    }
    TEST_ASSERT_TRUE(rethrown);
    int ran = 0;  // still serving after an exception
    side.start([&] { ran++; });
    TEST_ASSERT_TRUE(side.finish() == nullptr);
    TEST_ASSERT_EQUAL_INT(1, ran);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_prefetch_order_end_and_errors);
    RUN_TEST(test_side_thread_runs_beside_its_caller);
    RUN_TEST(test_gym_jump_same_output_with_prefetch);
    RUN_TEST(test_people_walking_same_output_with_prefetch);
    return UNITY_END();
}
