#!/usr/bin/env python3
"""The converted BlazePose models (tools/fetch_models.sh, tools/tflite_onnx.py).

Runs in the venv .venv/ (GS_VENV; re-executes itself there), on models/ (GS_MODELS_DIR): each ONNX model is run by
OpenCV 4.6's DNN module (Debian's python3-opencv, the same build as the C++
library) and compared with the original TFLite model run by the TFLite
interpreter (ai-edge-litert), on random inputs and on two real photos shipped
by Debian's opencv-doc (messi5.jpg, basketball1.png). On the photos the
detector must find the person and the landmark models must put the nose, hips
and ankles inside regions marked by hand on the images. Also: every file
matches the sums pinned in tools/fetch_models.sh, the conversion is
byte-for-byte repeatable, and the spec-strict form passes onnx.checker.
Missing models or venv are a failure: setup (tools/fetch_models.sh) makes them.
"""
import os
import sys

TOP = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# GS_MODELS_DIR and GS_VENV point elsewhere (as for the programs: a worktree
# sharing another checkout's fetched models)
VENV = os.environ.get("GS_VENV") or os.path.join(TOP, ".venv")
MODELS = os.environ.get("GS_MODELS_DIR") or os.path.join(TOP, "models")
HINT = "run tools/fetch_models.sh (setup makes the venv and the models)"

if os.path.realpath(sys.prefix) != os.path.realpath(VENV):
    py = os.path.join(VENV, "bin", "python")
    if not os.access(py, os.X_OK):
        print("test_models: FAIL: no venv at %s; %s" % (VENV, HINT))
        sys.exit(1)
    os.execv(py, [py, os.path.abspath(__file__)] + sys.argv[1:])

import hashlib  # noqa: E402
import importlib.util  # noqa: E402
import re  # noqa: E402
import subprocess  # noqa: E402
import tempfile  # noqa: E402
import unittest  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402
import onnx  # noqa: E402
from ai_edge_litert.interpreter import Interpreter, OpResolverType  # noqa: E402

DATA = "/usr/share/doc/opencv-doc/examples/data"
DETECTOR = "pose_detection"
LANDMARKS = ["pose_landmark_lite", "pose_landmark_full", "pose_landmark_heavy"]
LM_OUT = ["Identity", "Identity_1", "Identity_2", "Identity_3", "Identity_4"]
NOSEG_OUT = ["Identity", "Identity_1", "Identity_3", "Identity_4"]

# Largest |ONNX in OpenCV - TFLite| allowed, per output, in the output's own unit.
TOL = {
    ("det", "Identity"): 5e-3,      # box/keypoint offsets, px of the 224 input (values up to ~800)
    ("det", "Identity_1"): 2e-3,    # person logit (up to ~250 on noise)
    ("lm", "Identity"): 5e-3,       # x, y, z in px of the 256 crop (up to ~260); two logits
    ("lm", "Identity_1"): 1e-4,     # pose presence, already a probability
    ("lm", "Identity_2"): 3e-3,     # segmentation: compared as probabilities (logits reach 1e3)
    ("lm", "Identity_3"): 3e-3,     # heatmap (values up to ~110)
    ("lm", "Identity_4"): 1e-4,     # world landmarks, metres
}

# Hand-marked regions (x0, y0, x1, y1) in image pixels for the main person of each photo.
REGIONS = {
    "messi5.jpg": {"nose": (225, 85, 270, 130), "mid_hip": (240, 205, 300, 260),
                   "left_ankle": (395, 250, 455, 300), "right_ankle": (260, 290, 320, 340)},
    "basketball1.png": {"nose": (80, 105, 110, 135), "mid_hip": (55, 240, 120, 300),
                        "left_ankle": (105, 420, 150, 475), "right_ankle": (45, 415, 90, 475)},
}
BP = {"nose": 0, "left_hip": 23, "right_hip": 24, "left_ankle": 27, "right_ankle": 28}

REPORT = []  # (what, output, max abs diff, tolerance) printed at the end


def path(name):
    return os.path.join(MODELS, name)


def pinned_sums():
    """file name -> sha256 from the heredocs of tools/fetch_models.sh."""
    with open(os.path.join(TOP, "tools", "fetch_models.sh")) as f:
        text = f.read()
    return {m.group(2): m.group(1) for m in re.finditer(r"^([0-9a-f]{64})  (\S+)$", text, re.M)}


def sha256(p):
    h = hashlib.sha256()
    with open(p, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def sigmoid(x):
    return 1.0 / (1.0 + np.exp(-np.clip(x, -80, 80)))


def run_tflite(name, nhwc, xnnpack=False):
    """TFLite's outputs; its plain reference kernels unless xnnpack (its default CPU delegate)."""
    kw = {} if xnnpack else {"experimental_op_resolver_type": OpResolverType.BUILTIN_WITHOUT_DEFAULT_DELEGATES}
    it = Interpreter(model_path=path(name + ".tflite"), **kw)
    it.allocate_tensors()
    it.set_tensor(it.get_input_details()[0]["index"], np.ascontiguousarray(nhwc, dtype=np.float32))
    it.invoke()
    return {d["name"]: it.get_tensor(d["index"]).copy() for d in it.get_output_details()}


def run_opencv(onnx_file, nchw, names):
    net = cv2.dnn.readNetFromONNX(path(onnx_file))
    net.setInput(np.ascontiguousarray(nchw, dtype=np.float32))
    return dict(zip(names, net.forward(names)))


def detector_anchors():
    """The 2254 SSD anchor centres (strides 8, 16, 32, 32, 32; 2 per cell; fixed size)."""
    out = []
    for stride, per_cell in ((8, 2), (16, 2), (32, 6)):
        fm = 224 // stride
        for y in range(fm):
            for x in range(fm):
                out += [((x + 0.5) / fm, (y + 0.5) / fm)] * per_cell
    return np.array(out)


class Models(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        missing = [f for f in pinned_sums() if not os.path.exists(path(f))]
        if missing:
            raise AssertionError("models missing in %s: %s; %s" % (MODELS, ", ".join(missing), HINT))

    def compare(self, what, kind, ref, got, xnn=None):
        """OpenCV's outputs against TFLite's reference kernels; xnn (TFLite's XNNPACK
        outputs, if given) shows how far TFLite's own two CPU back ends differ."""
        for name, r in ref.items():
            g = got[name]  # TFLite's own shape and element order
            self.assertEqual(g.shape, r.shape, "%s output %s shape" % (what, name))
            x = xnn[name] if xnn is not None else None
            if (kind, name) == ("lm", "Identity_2"):
                r, g = sigmoid(r), sigmoid(g)
                x = sigmoid(x) if x is not None else None
            d = float(np.abs(r - g).max())
            own = float(np.abs(r - x).max()) if x is not None else float("nan")
            tol = TOL[(kind, name)]
            REPORT.append((what, name, d, own, tol, float(np.abs(r).max())))
            self.assertLessEqual(d, tol, "%s output %s: max |OpenCV - TFLite| = %.3g" % (what, name, d))

    def test_pinned_sums_and_detector_identity(self):
        for f, want in pinned_sums().items():
            self.assertEqual(sha256(path(f)), want, "%s differs from the sum pinned in tools/fetch_models.sh" % f)
        with open(path("pose_detection.tflite"), "rb") as f:
            self.assertEqual(f.read(8)[4:], b"TFL3", "detector is not a TFLite flatbuffer")

    def test_conversion_is_repeatable(self):
        conv = self._converter()
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "lite.onnx")
            conv.convert_file(path("pose_landmark_lite.tflite"), out)
            self.assertEqual(sha256(out), sha256(path("pose_landmark_lite.onnx")))

    def test_folded_weights_equal_the_interpreters(self):
        """Every DENSIFY/DEQUANTIZE result the converter computes equals, bit for bit,
        the tensor TFLite's interpreter computes for the same op."""
        conv = self._converter()
        for name in (DETECTOR, "pose_landmark_lite"):
            with open(path(name + ".tflite"), "rb") as f:
                c = conv.Converter(f.read())
            c.convert()
            it = Interpreter(model_path=path(name + ".tflite"), experimental_preserve_all_tensors=True,
                             experimental_op_resolver_type=OpResolverType.BUILTIN_WITHOUT_DEFAULT_DELEGATES)
            it.allocate_tensors()
            inp = it.get_input_details()[0]
            it.set_tensor(inp["index"], np.zeros(inp["shape"], np.float32))
            it.invoke()
            counts = {"DENSIFY": 0, "DEQUANTIZE": 0}
            for i in range(c.g.OperatorsLength()):
                op = c.g.Operators(i)
                kind = conv.opcode_name(c.model, op)
                if kind in counts:
                    out = op.Outputs(0)
                    ref, mine = it.get_tensor(out), c.const[out]
                    self.assertEqual(ref.dtype, mine.dtype, c.tname(out))
                    self.assertTrue(np.array_equal(ref, mine), "%s %s differs" % (kind, c.tname(out)))
                    counts[kind] += 1
            want = {DETECTOR: {"DENSIFY": 38, "DEQUANTIZE": 144},
                    "pose_landmark_lite": {"DENSIFY": 0, "DEQUANTIZE": 176}}[name]
            self.assertEqual(counts, want, name)

    def test_bad_input_is_a_clear_error(self):
        with open(path("pose_landmark_lite.tflite"), "rb") as f:
            head = f.read(1 << 20)
        with tempfile.TemporaryDirectory() as tmp:
            for name, data, says in (("cut.tflite", head, "damaged TFLite file"),
                                     ("text.tflite", b"hello world\n", "not a TFLite flatbuffer")):
                src = os.path.join(tmp, name)
                with open(src, "wb") as f:
                    f.write(data)
                out = os.path.join(tmp, "out.onnx")
                r = subprocess.run([sys.executable, os.path.join(TOP, "tools", "tflite_onnx.py"), src, out],
                                   capture_output=True, text=True)
                self.assertEqual(r.returncode, 1, r.stderr)
                self.assertIn("tflite_onnx: %s: %s" % (src, says), r.stderr)
                self.assertNotIn("Traceback", r.stderr)
                self.assertFalse(os.path.exists(out))

    def test_strict_form_is_valid_onnx(self):
        conv = self._converter()
        with tempfile.TemporaryDirectory() as tmp:
            for name, outs in ((DETECTOR, {"Identity": [1, 2254, 12], "Identity_1": [1, 2254, 1]}),
                               ("pose_landmark_lite", {"Identity": [1, 195], "Identity_1": [1, 1],
                                                       "Identity_2": [1, 256, 256, 1],
                                                       "Identity_3": [1, 64, 64, 39], "Identity_4": [1, 117]})):
                out = os.path.join(tmp, name + ".onnx")
                conv.convert_file(path(name + ".tflite"), out, strict_clip=True)
                m = onnx.load(out)
                onnx.checker.check_model(m, full_check=True)
                inferred = onnx.shape_inference.infer_shapes(m, strict_mode=True)
                shapes = {o.name: [d.dim_value for d in o.type.tensor_type.shape.dim] for o in inferred.graph.output}
                self.assertEqual(shapes, outs, name)
                ops = {n.op_type for n in m.graph.node}
                self.assertFalse(ops & {"GatherND"}, name)
            # the OpenCV form differs only in Clip taking attributes
            ocv = onnx.load(path(DETECTOR + ".onnx"))
            clips = [n for n in ocv.graph.node if n.op_type == "Clip"]
            self.assertTrue(clips and all(len(n.input) == 1 and {a.name for a in n.attribute} == {"min", "max"}
                                          for n in clips))

    def test_random_inputs(self):
        rng = np.random.default_rng(4)
        x = rng.uniform(-1, 1, (1, 224, 224, 3)).astype(np.float32)
        ref = run_tflite(DETECTOR, x)
        got = run_opencv(DETECTOR + ".onnx", x.transpose(0, 3, 1, 2), list(ref))
        self.compare("detector/random", "det", ref, got, run_tflite(DETECTOR, x, xnnpack=True))
        x = rng.uniform(0, 1, (1, 256, 256, 3)).astype(np.float32)
        for m in LANDMARKS:
            ref = run_tflite(m, x)
            self.assertEqual(sorted(ref), LM_OUT)
            got = run_opencv(m + ".onnx", x.transpose(0, 3, 1, 2), LM_OUT)
            self.compare(m[14:] + "/random", "lm", ref, got, run_tflite(m, x, xnnpack=True))
            noseg = run_opencv(m + "_noseg.onnx", x.transpose(0, 3, 1, 2), NOSEG_OUT)
            for n in NOSEG_OUT:  # the pruned model is the same sub-graph
                np.testing.assert_array_equal(noseg[n], got[n], "%s_noseg %s" % (m, n))

    def test_real_photos(self):
        anchors = detector_anchors()
        for photo, regions in REGIONS.items():
            img = cv2.imread(os.path.join(DATA, photo))
            self.assertIsNotNone(img, "%s/%s missing: apt-get install opencv-doc" % (DATA, photo))
            h, w = img.shape[:2]
            side = max(h, w)
            ox, oy = (side - w) // 2, (side - h) // 2
            square = cv2.copyMakeBorder(img, oy, side - h - oy, ox, side - w - ox, cv2.BORDER_CONSTANT)
            blob = cv2.dnn.blobFromImage(square, 1 / 127.5, (224, 224), (127.5, 127.5, 127.5), swapRB=True)
            ref = run_tflite(DETECTOR, blob.transpose(0, 2, 3, 1))
            got = run_opencv(DETECTOR + ".onnx", blob, list(ref))
            self.compare("detector/" + photo, "det", ref, got,
                         run_tflite(DETECTOR, blob.transpose(0, 2, 3, 1), xnnpack=True))
            scores = sigmoid(got["Identity_1"][0, :, 0])
            best = int(scores.argmax())
            self.assertGreater(scores[best], 0.5, "%s: no person found" % photo)
            raw = got["Identity"][0, best]
            kp = np.array([[raw[4 + 2 * k] / 224 + anchors[best, 0], raw[5 + 2 * k] / 224 + anchors[best, 1]]
                           for k in range(2)]) * side - [ox, oy]
            self.assertIn_region(kp[0], regions["mid_hip"], "%s detector hip centre" % photo)
            # MediaPipe's ROI: centre at keypoint 0, side 2.5 x |kp1 - kp0|, kp0 -> kp1 turned to point up
            d = kp[1] - kp[0]
            size = 2.5 * np.linalg.norm(d)
            ey = -d / np.linalg.norm(d)
            ex = np.array([ey[1], -ey[0]])
            c = kp[0]
            src = np.float32([c - (ex + ey) * size / 2, c + (ex - ey) * size / 2, c + (ey - ex) * size / 2])
            warp = cv2.getAffineTransform(src, np.float32([[0, 0], [256, 0], [0, 256]]))
            crop = cv2.warpAffine(img, warp, (256, 256), flags=cv2.INTER_LINEAR)
            lblob = cv2.dnn.blobFromImage(crop, 1 / 255.0, (256, 256), (0, 0, 0), swapRB=True)
            for m in LANDMARKS:
                ref = run_tflite(m, lblob.transpose(0, 2, 3, 1))
                got = run_opencv(m + ".onnx", lblob, LM_OUT)
                self.compare("%s/%s" % (m[14:], photo), "lm", ref, got,
                             run_tflite(m, lblob.transpose(0, 2, 3, 1), xnnpack=True))
                self.assertGreater(float(got["Identity_1"].ravel()[0]), 0.5, "%s %s: presence" % (m, photo))
                pts = got["Identity"].reshape(39, 5)
                img_pts = np.array([c + ex * (x / 256 - 0.5) * size + ey * (y / 256 - 0.5) * size
                                    for x, y in pts[:, :2]])
                where = "%s on %s" % (m, photo)
                self.assertIn_region(img_pts[BP["nose"]], regions["nose"], where + " nose")
                self.assertIn_region((img_pts[BP["left_hip"]] + img_pts[BP["right_hip"]]) / 2,
                                     regions["mid_hip"], where + " mid-hip")
                self.assertIn_region(img_pts[BP["left_ankle"]], regions["left_ankle"], where + " left ankle")
                self.assertIn_region(img_pts[BP["right_ankle"]], regions["right_ankle"], where + " right ankle")

    def assertIn_region(self, p, box, what):
        x0, y0, x1, y1 = box
        self.assertTrue(x0 <= p[0] <= x1 and y0 <= p[1] <= y1,
                        "%s at (%.0f, %.0f), outside the marked region %s" % (what, p[0], p[1], box))

    @staticmethod
    def _converter():
        spec = importlib.util.spec_from_file_location("tflite_onnx", os.path.join(TOP, "tools", "tflite_onnx.py"))
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        return mod


if __name__ == "__main__":
    prog = unittest.main(exit=False, verbosity=2)
    if REPORT:
        print("max |OpenCV 4.6 DNN - TFLite reference kernels| per output; for scale, max |TFLite XNNPACK -"
              " TFLite reference|, the tolerance and max |value| (segmentation as probabilities):")
        for what, name, d, own, tol, rng_ in REPORT:
            print("  %-26s %-10s %.2e  (TFLite's own %.2e, tol %.0e, max |ref| %.3g)" % (what, name, d, own, tol, rng_))
    sys.exit(0 if prog.result.wasSuccessful() else 1)
