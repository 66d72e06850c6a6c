// pose_engine.hpp - the inference engine under the pose networks: OpenCV's DNN
// module (always built, the fallback) or OpenVINO (when CMake found its package,
// installed at setup by tools/fetch_engine.sh: GS_HAVE_OPENVINO). Both run the
// same converted ONNX graphs (OpenVINO the spec form of Clip, `*_strict.onnx`,
// docs/models.md) and give the same outputs to float noise (docs/pose.md).
#ifndef GS_POSE_ENGINE_HPP
#define GS_POSE_ENGINE_HPP

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace gs {

// automatic: OpenVINO when built in, else OpenCV.
enum class PoseEngine { automatic, opencv, openvino };
const char *pose_engine_name(PoseEngine e);
// "auto", "opencv" or "openvino"; false for anything else
bool pose_engine_from_name(const std::string &s, PoseEngine *out);
// opencv always; openvino when this build has it
bool pose_engine_built(PoseEngine e);
// automatic -> the engine it stands for in this build; the others unchanged
PoseEngine pose_engine_resolve(PoseEngine e);

// One loaded network: a 1 x 3 x H x W float input, its outputs by name.
class PoseNet {
public:
    virtual ~PoseNet() = default;
    virtual std::vector<std::string> output_names() = 0;
    // Runs blob; outs[i] is output names[i] (float, the engine's shape), valid
    // until the next run. Throws cv::Exception on an engine error.
    virtual void run(const cv::Mat &blob, const std::vector<std::string> &names, std::vector<cv::Mat> &outs) = 0;
};

// The CPUs this process may run on (taskset, cpusets), at least 1.
int allowed_cpus();

// Where OpenVINO keeps the networks it compiled, so that later runs load them
// instead of compiling again (about 5 times faster; keyed by the model file,
// the settings and OpenVINO's version): GS_POSE_CACHE (a folder, or "off" for
// none), else $XDG_CACHE_HOME/gravscale/openvino, else ~/.cache/gravscale/openvino;
// empty: no cache.
std::string pose_engine_cache_dir();

// The network in path run by engine e (not automatic) on threads CPU threads
// (0: the engine's default, the CPUs this process may use). nullptr with err
// set when it cannot be loaded or e is not built. OpenCV's thread count is
// process-wide (cv::setNumThreads); OpenVINO's is the network's own.
std::unique_ptr<PoseNet> pose_net_load(PoseEngine e, const std::string &path, int threads, std::string &err);

}  // namespace gs

#endif
