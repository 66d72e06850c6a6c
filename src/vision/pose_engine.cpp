// pose_engine.cpp - OpenCV DNN and (when built) OpenVINO behind PoseNet.
#include "pose_engine.hpp"

#include <sched.h>
#include <sys/stat.h>

#include <cstdlib>

#include <opencv2/dnn.hpp>

#if GS_HAVE_OPENVINO
#include <openvino/openvino.hpp>
#endif

namespace gs {

const char *pose_engine_name(PoseEngine e)
{
    switch (e) {
    case PoseEngine::automatic: return "auto";
    case PoseEngine::opencv: return "opencv";
    case PoseEngine::openvino: return "openvino";
    }
    return "?";
}

bool pose_engine_from_name(const std::string &s, PoseEngine *out)
{
    for (PoseEngine e : {PoseEngine::automatic, PoseEngine::opencv, PoseEngine::openvino}) {
        if (s == pose_engine_name(e)) {
            *out = e;
            return true;
        }
    }
    return false;
}

bool pose_engine_built(PoseEngine e)
{
    return e == PoseEngine::openvino ? GS_HAVE_OPENVINO != 0 : true;
}

PoseEngine pose_engine_resolve(PoseEngine e)
{
    if (e != PoseEngine::automatic) return e;
    return GS_HAVE_OPENVINO ? PoseEngine::openvino : PoseEngine::opencv;
}

namespace {

class OpenCvNet : public PoseNet {
public:
    cv::dnn::Net net;
    std::vector<std::string> output_names() override
    {
        std::vector<std::string> v;
        for (const cv::String &s : net.getUnconnectedOutLayersNames()) v.push_back(s);
        return v;
    }
    void run(const cv::Mat &blob, const std::vector<std::string> &names, std::vector<cv::Mat> &outs) override
    {
        net.setInput(blob);
        std::vector<cv::String> n(names.begin(), names.end());
        net.forward(outs, n);
    }
};

#if GS_HAVE_OPENVINO
class OpenVinoNet : public PoseNet {
public:
    ov::CompiledModel model;
    ov::InferRequest req;
    std::vector<std::string> output_names() override
    {
        std::vector<std::string> v;
        for (const ov::Output<const ov::Node> &o : model.outputs()) v.push_back(o.get_any_name());
        return v;
    }
    void run(const cv::Mat &blob, const std::vector<std::string> &names, std::vector<cv::Mat> &outs) override
    {
        CV_Assert(blob.type() == CV_32F && blob.isContinuous() && blob.dims == 4);
        ov::Shape shape;
        for (int i = 0; i < blob.dims; i++) shape.push_back(static_cast<size_t>(blob.size[i]));
        try {
            // the blob's own memory: no copy (the request only reads it during infer)
            req.set_input_tensor(ov::Tensor(ov::element::f32, shape, const_cast<float *>(blob.ptr<float>())));
            req.infer();
            outs.resize(names.size());
            for (size_t i = 0; i < names.size(); i++) {
                ov::Tensor t = req.get_tensor(names[i]);
                std::vector<int> dims;
                for (size_t d : t.get_shape()) dims.push_back(static_cast<int>(d));
                outs[i] = cv::Mat(dims, CV_32F, t.data<float>());  // valid until the next infer
            }
        } catch (const std::exception &e) {
            CV_Error(cv::Error::StsError, std::string("OpenVINO: ") + e.what());
        }
    }
};
#endif

}  // namespace

int allowed_cpus()
{
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof set, &set) != 0) return 1;
    int n = CPU_COUNT(&set);
    return n > 0 ? n : 1;
}

std::string pose_engine_cache_dir()
{
    const char *env = std::getenv("GS_POSE_CACHE");
    if (env) return std::string(env) == "off" ? std::string() : std::string(env);
    const char *xdg = std::getenv("XDG_CACHE_HOME");
    if (xdg && *xdg == '/') return std::string(xdg) + "/gravscale/openvino";
    const char *home = std::getenv("HOME");
    if (home && *home == '/') return std::string(home) + "/.cache/gravscale/openvino";
    return std::string();
}

std::unique_ptr<PoseNet> pose_net_load(PoseEngine e, const std::string &path, int threads, std::string &err)
{
    e = pose_engine_resolve(e);
    if (e == PoseEngine::opencv) {
        std::unique_ptr<OpenCvNet> n(new OpenCvNet);
        try {
            n->net = cv::dnn::readNet(path);
        } catch (const cv::Exception &ex) {
            err = "cannot load pose model " + path + ": " + ex.what();
            return nullptr;
        }
        if (n->net.empty()) {
            err = "cannot load pose model " + path;
            return nullptr;
        }
        n->net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
        n->net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
        return n;
    }
#if GS_HAVE_OPENVINO
    static ov::Core core;  // one per process: it holds the loaded device plugins
    // f32: the CPU's default bf16/f16 shifts the outputs by ~0.5 %; no pinning: the
    // machine's other work and taskset decide where the threads run
    ov::AnyMap props{ov::hint::inference_precision(ov::element::f32),
                     ov::hint::performance_mode(ov::hint::PerformanceMode::LATENCY),
                     ov::hint::enable_cpu_pinning(false),
                     ov::inference_num_threads(threads > 0 ? threads : allowed_cpus())};
    // OpenVINO keys a file's cache entry by its path: its size and time name a folder
    // of their own, so a model converted again is compiled again
    std::string cache = pose_engine_cache_dir();
    struct stat st;
    if (!cache.empty() && stat(path.c_str(), &st) == 0)
        cache += "/" + std::to_string(static_cast<long long>(st.st_size)) + "-" +
                 std::to_string(static_cast<long long>(st.st_mtim.tv_sec)) + "." +
                 std::to_string(static_cast<long long>(st.st_mtim.tv_nsec));
    else
        cache.clear();
    for (int cached = cache.empty() ? 0 : 1; cached >= 0; cached--) {
        try {
            std::unique_ptr<OpenVinoNet> n(new OpenVinoNet);
            ov::AnyMap p = props;
            if (cached) p.emplace(ov::cache_dir.name(), cache);
            n->model = core.compile_model(path, "CPU", p);
            n->req = n->model.create_infer_request();
            return n;
        } catch (const std::exception &ex) {
            // a cache that cannot be written or read: compiled without it
            if (!cached) err = "cannot load pose model " + path + " in OpenVINO: " + ex.what();
        }
    }
    return nullptr;
#else
    (void)threads;
    err = "this build has no OpenVINO (tools/fetch_engine.sh installs it, then configure again)";
    return nullptr;
#endif
}

}  // namespace gs
