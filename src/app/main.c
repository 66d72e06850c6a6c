/* main.c - the gravscale program: dispatch to a subcommand. */
#include <stdio.h>
#include <string.h>

#include "gravscale/gs_types.h"

/* Defined in cmd_replay.c (no app header yet: one prototype per side). */
int gs_cmd_replay(int argc, char **argv);

#ifdef GS_VISION_MODULE
#include <dlfcn.h>
#include <limits.h>
#include <unistd.h>

/* video and cam: gs_cmd_video / gs_cmd_cam (cmd_video.cpp, cmd_cam.cpp) in the
 * module next to this program, loaded only now so that replay never maps OpenCV. */
static int run_vision(const char *cmd, const char *entry, int argc, char **argv)
{
    char path[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", path, sizeof path - 1);
    if (n <= 0) {
        fprintf(stderr, "gravscale: %s: cannot find this program's directory (/proc/self/exe)\n", cmd);
        return 2;
    }
    path[n] = '\0';
    char *slash = strrchr(path, '/');
    size_t dir = slash ? (size_t)(slash - path) + 1 : 0;
    if (dir + sizeof GS_VISION_MODULE > sizeof path) {
        fprintf(stderr, "gravscale: %s: program path too long\n", cmd);
        return 2;
    }
    memcpy(path + dir, GS_VISION_MODULE, sizeof GS_VISION_MODULE);
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        fprintf(stderr, "gravscale: %s: the vision commands' library %s could not be loaded (%s); "
                        "it is built with the program and must sit next to it\n",
                cmd, path, dlerror());
        return 2;
    }
    int (*fn)(int, char **);
    *(void **)&fn = dlsym(h, entry); /* POSIX's way from an object pointer to a function */
    if (!fn) {
        fprintf(stderr, "gravscale: %s: %s has no %s (%s)\n", cmd, path, entry, dlerror());
        return 2;
    }
    return fn(argc, argv); /* the module stays loaded until exit: its atexit handlers need it */
}
#endif

static void usage(FILE *f)
{
    fputs("usage: gravscale COMMAND [OPTIONS]\n"
          "\n"
          "Measure a person's or an object's metric size from an uncalibrated static\n"
          "camera, using gravity as the ruler during free flight.\n"
          "\n"
          "commands:\n"
          "  replay     read recorded keypoints (CSV, AlphaPose, OpenPose) and report\n"
          "             jumps and the height as JSON Lines or NMEA sentences\n"
          "  video      find a person (BlazePose, --detector pose) or a ball (--detector\n"
          "             ball) in a video file or an image sequence and report their\n"
          "             flights, height or diameter the same way\n"
          "  cam        the device daemon: a live camera (V4L2, libcamera, GStreamer) or\n"
          "             a file, events to stdout, file, serial, TCP, UDP and MQTT sinks,\n"
          "             and the kiosk's results page ([kiosk]: docs/kiosk.md)\n"
          "\n"
          "options:\n"
          "  --help     this text\n"
          "  --version  print the version\n"
          "\n"
          "gravscale COMMAND --help describes a command. Exit codes: 0 ok, 1 bad input\n"
          "data, 2 usage or config error, 3 I/O error writing output.\n",
          f);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    const char *cmd = argv[1];
    if (strcmp(cmd, "--help") == 0 || strcmp(cmd, "-h") == 0 || strcmp(cmd, "help") == 0) {
        usage(stdout);
        return fflush(stdout) == 0 ? 0 : 3;
    }
    if (strcmp(cmd, "--version") == 0) {
        fputs("gravscale " GS_VERSION "\n", stdout);
        return fflush(stdout) == 0 ? 0 : 3;
    }
    if (strcmp(cmd, "replay") == 0)
        return gs_cmd_replay(argc - 1, argv + 1);
    if (strcmp(cmd, "video") == 0) {
#ifdef GS_VISION_MODULE
        return run_vision("video", "gs_cmd_video", argc - 1, argv + 1);
#else
        fputs("gravscale: built without OpenCV: the video command is not available "
              "(install libopencv-dev and libavformat-dev, then rebuild)\n", stderr);
        return 2;
#endif
    }
    if (strcmp(cmd, "cam") == 0) {
#ifdef GS_VISION_MODULE
        return run_vision("cam", "gs_cmd_cam", argc - 1, argv + 1);
#else
        fputs("gravscale: built without OpenCV: the cam command is not available "
              "(install libopencv-dev and libavformat-dev, then rebuild)\n", stderr);
        return 2;
#endif
    }
    fprintf(stderr, "gravscale: unknown command '%s' (see gravscale --help)\n", cmd);
    return 2;
}
