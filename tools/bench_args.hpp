// bench_args.hpp - what the C++ benchmarks (bench_pipeline, bench_pose) share:
// the default clip and their "--name VALUE" options, each value checked.
#ifndef GS_BENCH_ARGS_HPP
#define GS_BENCH_ARGS_HPP

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <initializer_list>
#include <sstream>
#include <string>
#include <vector>

namespace gs_bench {

// The gym clip of ../shared (GS_SHARED_DIR overrides the folder).
inline std::string gym_clip()
{
    const char *shared = std::getenv("GS_SHARED_DIR");
    return std::string(shared && *shared ? shared : "../shared") +
           "/data/real/jumpvision_jumps/cmj_gym_handheld_30fps.mp4";
}

struct Option {
    const char *name;   // "--model"
    std::string *text;  // its value
};

// "--name VALUE" for every name in opts; one bare argument goes to *positional.
// false: an unknown option, a missing value or a second bare argument.
inline bool parse_options(int argc, char **argv, std::initializer_list<Option> opts, std::string *positional)
{
    bool have_positional = false;
    for (int i = 1; i < argc; i++) {
        std::string a = argv[i];
        if (a.empty() || a[0] != '-') {
            if (have_positional || !positional) return false;
            *positional = a;
            have_positional = true;
            continue;
        }
        const Option *hit = nullptr;
        for (const Option &o : opts)
            if (a == o.name) hit = &o;
        if (!hit || i + 1 >= argc) return false;
        *hit->text = argv[++i];
    }
    return true;
}

// Every choice when text is the word `every` ("all", "both"), else a comma-separated
// list of them; false on anything else or an empty list.
inline bool pick(const std::string &text, const char *every, const std::vector<std::string> &choices,
                 std::vector<std::string> &out)
{
    out.clear();
    if (text == every) {
        out = choices;
        return true;
    }
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        bool ok = false;
        for (const std::string &c : choices) ok = ok || item == c;
        if (!ok) return false;
        out.push_back(item);
    }
    return !out.empty();
}

// pick() for whole numbers given as text ("720", "1080").
inline bool pick_ints(const std::string &text, const char *every, const std::vector<std::string> &choices,
                      std::vector<int> &out)
{
    std::vector<std::string> s;
    if (!pick(text, every, choices, s)) return false;
    out.clear();
    for (const std::string &x : s) out.push_back(std::atoi(x.c_str()));  // choices are numbers
    return true;
}

// A whole number >= lo written out in full; false otherwise (out untouched).
inline bool to_int(const std::string &text, long lo, int &out)
{
    char *end = nullptr;
    errno = 0;
    long v = std::strtol(text.c_str(), &end, 10);
    if (text.empty() || *end || errno || v < lo || v > 1000000000L) return false;
    out = static_cast<int>(v);
    return true;
}

// A finite number >= 0 written out in full; false otherwise (out untouched).
inline bool to_seconds(const std::string &text, double &out)
{
    char *end = nullptr;
    double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end || !std::isfinite(v) || v < 0) return false;
    out = v;
    return true;
}

}  // namespace gs_bench

#endif
