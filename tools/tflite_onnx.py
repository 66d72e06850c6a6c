#!/usr/bin/env python3
"""Convert the BlazePose TFLite models to ONNX that OpenCV 4.6's DNN module loads.

    tools/tflite_onnx.py IN.tflite OUT.onnx [--outputs A,B] [--strict-clip]
    tools/tflite_onnx.py IN.tflite --list-ops

Reads the flatbuffer with the PyPI package `tflite`, folds every constant
sub-graph (sparse DENSIFY and fp16 DEQUANTIZE weights) into plain float32
initializers and emits an NCHW graph:
  - the graph input is NCHW [1, 3, H, W] (what cv2.dnn.blobFromImage gives); it
    is the TFLite NHWC input transposed once, at the boundary;
  - 4-D activations stay NCHW inside; a tensor is turned back into TFLite's own
    layout only where a layout-blind op (RESHAPE, a graph output) needs it, so
    every graph output keeps TFLite's name, shape and element order.
OpenCV 4.6 quirks handled: Clip takes min/max as attributes (its importer
rejects Clip with inputs; --strict-clip writes the spec-valid opset-11 form
with inputs, which onnx.checker accepts and OpenCV 4.6 does not), no GatherND
is used, a zero PAD read only by convolutions is folded into their own pads.
Output is deterministic: same input and package pins, same bytes.
"""
import argparse
import sys

import numpy as np
import onnx
import tflite
from onnx import TensorProto, helper, numpy_helper
from tflite.ActivationFunctionType import ActivationFunctionType as AF
from tflite.BuiltinOperator import BuiltinOperator as BO
from tflite.DimensionType import DimensionType
from tflite.Padding import Padding
from tflite.SparseIndexVector import SparseIndexVector
from tflite.TensorType import TensorType

OPSET = 11  # Resize with half_pixel needs 11; OpenCV 4.6 reads it
OP_NAMES = {v: k for k, v in vars(BO).items() if not k.startswith("_")}
NP_TYPES = {
    TensorType.FLOAT32: np.float32, TensorType.FLOAT16: np.float16,
    TensorType.INT32: np.int32, TensorType.INT64: np.int64,
    TensorType.UINT8: np.uint8, TensorType.INT8: np.int8, TensorType.INT16: np.int16,
}
NHWC_TO_NCHW = [0, 3, 1, 2]
NCHW_TO_NHWC = [0, 2, 3, 1]


class ConvertError(Exception):
    pass


def opcode_name(model, op):
    oc = model.OperatorCodes(op.OpcodeIndex())
    code = max(oc.BuiltinCode(), oc.DeprecatedBuiltinCode())  # schema v3a moved the field
    if code == BO.CUSTOM:
        return "CUSTOM:" + oc.CustomCode().decode()
    return OP_NAMES.get(code, str(code))


def list_ops(model):
    """Op name -> count over the main subgraph, in first-use order."""
    g = model.Subgraphs(0)
    counts = {}
    for i in range(g.OperatorsLength()):
        n = opcode_name(model, g.Operators(i))
        counts[n] = counts.get(n, 0) + 1
    return counts


def _index_vector(union_type, table):
    cls = {SparseIndexVector.Int32Vector: tflite.Int32Vector,
           SparseIndexVector.Uint16Vector: tflite.Uint16Vector,
           SparseIndexVector.Uint8Vector: tflite.Uint8Vector}.get(union_type)
    if cls is None:
        raise ConvertError("sparse index vector of unknown type %d" % union_type)
    v = cls()
    v.Init(table.Bytes, table.Pos)
    return np.asarray(v.ValuesAsNumpy(), dtype=np.int64)


def densify(values, shape, sparsity):
    """Dense array from TFLite's sparse storage (CSR levels over a traversal order)."""
    if sparsity.BlockMapLength():
        raise ConvertError("sparse tensor with a block map is not handled")
    order = [int(d) for d in sparsity.TraversalOrderAsNumpy()]
    if sorted(order) != list(range(len(shape))):
        raise ConvertError("sparse traversal order %s does not match rank %d" % (order, len(shape)))
    ids = np.zeros(1, dtype=np.int64)  # position of each partial path inside its level
    coords = np.zeros((1, 0), dtype=np.int64)
    for level, dim in enumerate(order):
        dm = sparsity.DimMetadata(level)
        if dm.Format() == DimensionType.DENSE:
            n = dm.DenseSize()
            ids = (ids[:, None] * n + np.arange(n)).ravel()
            coords = np.concatenate([np.repeat(coords, n, axis=0),
                                     np.tile(np.arange(n), len(coords))[:, None]], axis=1)
        else:  # SPARSE_CSR: children of parent p are segments[p] .. segments[p+1]
            seg = _index_vector(dm.ArraySegmentsType(), dm.ArraySegments())
            idx = _index_vector(dm.ArrayIndicesType(), dm.ArrayIndices())
            start, stop = seg[ids], seg[ids + 1]
            counts = stop - start
            parent = np.repeat(np.arange(len(ids)), counts)
            offs = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
            ids = np.repeat(start, counts) + offs
            coords = np.concatenate([coords[parent], idx[ids][:, None]], axis=1)
    if len(ids) != values.size:
        raise ConvertError("sparse tensor: %d positions for %d values" % (len(ids), values.size))
    dense = np.zeros(shape, dtype=values.dtype)
    full = np.empty_like(coords)
    full[:, order] = coords  # traversal order -> tensor dimensions
    dense[tuple(full.T)] = values[ids]
    return dense


class Converter:
    def __init__(self, buf, strict_clip=False, keep=None):
        self.model = tflite.Model.GetRootAsModel(buf, 0)
        if self.model.SubgraphsLength() != 1:
            raise ConvertError("%d subgraphs; only one is handled" % self.model.SubgraphsLength())
        self.g = self.model.Subgraphs(0)
        self.strict_clip = strict_clip
        self.keep = keep  # output names to keep (None: all); the rest is pruned
        self.nodes, self.inits, self.names = [], [], set()
        self.const = {}    # tensor index -> numpy array
        self.act = {}      # tensor index -> (onnx name, layout 'nchw' | 'native')
        self.cache = {}    # (onnx name, wanted layout) -> onnx name
        self.fold_pad = {}  # tensor index of a PAD output -> (input tensor, [t, l, b, r])
        for i in range(self.g.TensorsLength()):
            self._load_const(i)

    # ---- tensors -------------------------------------------------------
    def tensor(self, i):
        return self.g.Tensors(i)

    def tname(self, i):
        return self.tensor(i).Name().decode()

    def shape(self, i):
        t = self.tensor(i)
        return [int(d) for d in t.ShapeAsNumpy()] if t.ShapeLength() else []

    def _load_const(self, i):
        t = self.tensor(i)
        data = self.model.Buffers(t.Buffer()).DataAsNumpy()
        if isinstance(data, int) or data.size == 0:
            return
        if t.Type() not in NP_TYPES:
            raise ConvertError("tensor %r: type %d not handled" % (self.tname(i), t.Type()))
        arr = np.frombuffer(data.tobytes(), dtype=NP_TYPES[t.Type()])
        if t.Sparsity() is None:
            arr = arr.reshape(self.shape(i))
        else:
            arr = arr.copy()  # raw sparse values; DENSIFY expands them
        self.const[i] = arr

    def unique(self, base):
        name, k = base, 1
        while name in self.names:
            name, k = "%s_%d" % (base, k), k + 1
        self.names.add(name)
        return name

    def init(self, base, arr):
        name = self.unique(base)
        self.inits.append(numpy_helper.from_array(np.ascontiguousarray(arr), name))
        return name

    def node(self, op_type, inputs, base, **attrs):
        out = self.unique(base)
        self.nodes.append(helper.make_node(op_type, inputs, [out], name=out, **attrs))
        return out

    def get(self, i, layout):
        """ONNX name of activation tensor i in the wanted layout ('nchw' or 'native')."""
        if i not in self.act:
            raise ConvertError("tensor %r is neither computed nor constant" % self.tname(i))
        name, have = self.act[i]
        if have == layout or len(self.shape(i)) != 4:
            return name
        key = (name, layout)
        if key not in self.cache:
            n, h, w, c = self.shape(i)
            perm = NCHW_TO_NHWC if layout == "native" else NHWC_TO_NCHW
            if c == 1 or h * w == 1:  # same memory order: a free reshape, not a copy
                target = [n, h, w, c] if layout == "native" else [n, c, h, w]
                shp = self.init(name + "_shape", np.array(target, dtype=np.int64))
                self.cache[key] = self.node("Reshape", [name, shp], name + "_" + layout)
            else:
                self.cache[key] = self.node("Transpose", [name], name + "_" + layout, perm=perm)
        return self.cache[key]

    def activation(self, name, fn, base):
        if fn == AF.NONE:
            return name
        if fn == AF.RELU:
            return self.node("Relu", [name], base + "_relu")
        if fn in (AF.RELU6, AF.RELU_N1_TO_1):
            lo, hi = (0.0, 6.0) if fn == AF.RELU6 else (-1.0, 1.0)
            if self.strict_clip:
                mn = self.init(base + "_min", np.array(lo, dtype=np.float32))
                mx = self.init(base + "_max", np.array(hi, dtype=np.float32))
                return self.node("Clip", [name, mn, mx], base + "_clip")
            return self.node("Clip", [name], base + "_clip", min=lo, max=hi)  # OpenCV 4.6 form
        if fn == AF.TANH:
            return self.node("Tanh", [name], base + "_tanh")
        raise ConvertError("fused activation %d not handled" % fn)

    # ---- ops -----------------------------------------------------------
    @staticmethod
    def same_pads(size, k, s, d):
        out = -(-size // s)
        total = max((out - 1) * s + (k - 1) * d + 1 - size, 0)
        return total // 2, total - total // 2

    def conv_pads(self, x, kh, kw, sh, sw, dh, dw, padding):
        """(input tensor, ONNX pads) with a foldable PAD in front absorbed."""
        if padding == Padding.SAME:
            _, h, w, _ = self.shape(x)
            t, b = self.same_pads(h, kh, sh, dh)
            l, r = self.same_pads(w, kw, sw, dw)
            pads = [t, l, b, r]
        else:
            pads = [0, 0, 0, 0]
        if x in self.fold_pad:
            src, extra = self.fold_pad[x]
            return src, [p + e for p, e in zip(pads, extra)]
        return x, pads

    def op_conv(self, op, opts, depthwise):
        x, wt = op.Inputs(0), op.Inputs(1)
        b = op.Inputs(2) if op.InputsLength() > 2 else -1
        if wt not in self.const or (b >= 0 and b not in self.const):
            raise ConvertError("convolution with non-constant weights")
        o = (tflite.DepthwiseConv2DOptions if depthwise else tflite.Conv2DOptions)()
        o.Init(opts.Bytes, opts.Pos)
        w = self.const[wt].astype(np.float32)
        cin = self.shape(x)[3]
        if depthwise:  # [1, KH, KW, C*M] -> [C*M, 1, KH, KW], one group per input channel
            w = w.transpose(3, 0, 1, 2)
            group = cin
        else:  # OHWI -> OIHW
            w = w.transpose(0, 3, 1, 2)
            group = 1
        kh, kw = w.shape[2], w.shape[3]
        src, pads = self.conv_pads(x, kh, kw, o.StrideH(), o.StrideW(),
                                   o.DilationHFactor(), o.DilationWFactor(), o.Padding())
        out_name = self.tname(op.Outputs(0))
        ins = [self.get(src, "nchw"), self.init(out_name + "_w", w)]
        if b >= 0:
            ins.append(self.init(out_name + "_b", self.const[b].astype(np.float32)))
        y = self.node("Conv", ins, out_name + ("_dw" if depthwise else "_conv"),
                      kernel_shape=[kh, kw], strides=[o.StrideH(), o.StrideW()],
                      dilations=[o.DilationHFactor(), o.DilationWFactor()],
                      pads=[pads[0], pads[1], pads[2], pads[3]], group=group)
        return self.activation(y, o.FusedActivationFunction(), out_name), "nchw"

    def op_pad(self, op):
        x, p = op.Inputs(0), op.Inputs(1)
        if p not in self.const:
            raise ConvertError("PAD with non-constant paddings")
        pads = self.const[p].astype(np.int64).reshape(-1, 2)
        out = op.Outputs(0)
        spatial_only = len(pads) == 4 and not pads[0].any() and not pads[3].any()
        consumers = self.consumers(out)
        is_output = any(self.g.Outputs(k) == out for k in range(self.g.OutputsLength()))
        foldable = spatial_only and consumers and not is_output and all(
            opcode_name(self.model, c) in ("CONV_2D", "DEPTHWISE_CONV_2D") and c.Inputs(0) == out
            for c in consumers)
        if foldable:  # zero padding in front of convolutions = the convolutions' own pads
            self.fold_pad[out] = (x, [int(pads[1][0]), int(pads[2][0]), int(pads[1][1]), int(pads[2][1])])
            return None, None
        if len(pads) == 4:
            name, layout = self.get(x, "nchw"), "nchw"
            pads = pads[NHWC_TO_NCHW]
        else:
            name, layout = self.get(x, "native"), "native"
        pv = self.init(self.tname(out) + "_pads", np.concatenate([pads[:, 0], pads[:, 1]]).astype(np.int64))
        return self.node("Pad", [name, pv], self.tname(out), mode="constant"), layout

    def consumers(self, t):
        res = []
        for i in range(self.g.OperatorsLength()):
            op = self.g.Operators(i)
            if any(op.Inputs(k) == t for k in range(op.InputsLength())):
                res.append(op)
        return res

    def op_add_mul(self, op, opts, onnx_op):
        a, b = op.Inputs(0), op.Inputs(1)
        o = (tflite.AddOptions if onnx_op == "Add" else tflite.MulOptions)()
        o.Init(opts.Bytes, opts.Pos)
        out = op.Outputs(0)
        layout = "nchw" if len(self.shape(out)) == 4 else "native"
        ins = []
        for t in (a, b):
            if t in self.const:
                c = self.const[t].astype(np.float32)
                if layout == "nchw" and c.ndim == 4:
                    c = c.transpose(NHWC_TO_NCHW)
                elif layout == "nchw" and c.ndim == 1:  # per-channel vector broadcasts over C
                    c = c.reshape(1, -1, 1, 1)
                elif layout == "nchw" and c.ndim != 0:
                    raise ConvertError("broadcast of a rank-%d constant in %s" % (c.ndim, onnx_op))
                ins.append(self.init(self.tname(out) + "_k", c))
            else:
                if len(self.shape(t)) != len(self.shape(out)):
                    raise ConvertError("%s of tensors of different rank" % onnx_op)
                ins.append(self.get(t, layout))
        y = self.node(onnx_op, ins, self.tname(out) + "_" + onnx_op.lower())
        return self.activation(y, o.FusedActivationFunction(), self.tname(out)), layout

    def op_maxpool(self, op, opts):
        x = op.Inputs(0)
        o = tflite.Pool2DOptions()
        o.Init(opts.Bytes, opts.Pos)
        kh, kw, sh, sw = o.FilterHeight(), o.FilterWidth(), o.StrideH(), o.StrideW()
        if o.Padding() == Padding.SAME:  # TF's SAME max-pool ignores padded cells, like ONNX's
            _, h, w, _ = self.shape(x)
            t, b = self.same_pads(h, kh, sh, 1)
            l, r = self.same_pads(w, kw, sw, 1)
        else:
            t = b = l = r = 0
        name = self.tname(op.Outputs(0))
        y = self.node("MaxPool", [self.get(x, "nchw")], name + "_pool", kernel_shape=[kh, kw],
                      strides=[sh, sw], pads=[t, l, b, r])
        return self.activation(y, o.FusedActivationFunction(), name), "nchw"

    def op_resize(self, op, opts):
        x = op.Inputs(0)
        o = tflite.ResizeBilinearOptions()
        o.Init(opts.Bytes, opts.Pos)
        _, h, w, _ = self.shape(x)
        _, h2, w2, _ = self.shape(op.Outputs(0))
        if o.AlignCorners():
            mode = "align_corners"
        elif o.HalfPixelCenters():  # OpenCV 4.6 reads this as its own half-pixel bilinear
            mode = "half_pixel"
        else:
            mode = "asymmetric"
        if h2 % h or w2 % w:
            raise ConvertError("resize by a non-integer factor %dx%d -> %dx%d" % (h, w, h2, w2))
        name = self.tname(op.Outputs(0))
        roi = self.init(name + "_roi", np.zeros(0, dtype=np.float32))
        scales = self.init(name + "_scales", np.array([1, 1, h2 // h, w2 // w], dtype=np.float32))
        return self.node("Resize", [self.get(x, "nchw"), roi, scales], name, mode="linear",
                         coordinate_transformation_mode=mode), "nchw"

    def op_depth_to_space(self, op, opts):
        o = tflite.DepthToSpaceOptions()
        o.Init(opts.Bytes, opts.Pos)
        # TF's NHWC depth_to_space takes channel (i*bs + j)*C' + c, as ONNX's DCR mode does
        return self.node("DepthToSpace", [self.get(op.Inputs(0), "nchw")], self.tname(op.Outputs(0)),
                         blocksize=o.BlockSize(), mode="DCR"), "nchw"

    def op_reshape(self, op):
        x, out = op.Inputs(0), op.Outputs(0)
        target = np.array(self.shape(out), dtype=np.int64)  # static: the output's own shape
        shp = self.init(self.tname(out) + "_shape", target)
        y = self.node("Reshape", [self.get(x, "native"), shp], self.tname(out))
        return y, "native"

    def op_concat(self, op, opts):
        o = tflite.ConcatenationOptions()
        o.Init(opts.Bytes, opts.Pos)
        ins = [op.Inputs(k) for k in range(op.InputsLength())]
        out = op.Outputs(0)
        rank = len(self.shape(out))
        axis = o.Axis() % rank
        nchw = rank == 4 and all(self.act.get(t, ("", "native"))[1] == "nchw" for t in ins)
        if nchw:
            axis = NHWC_TO_NCHW.index(axis)
        layout = "nchw" if nchw else "native"
        names = []
        for t in ins:
            if t in self.const:
                c = self.const[t].astype(np.float32)
                names.append(self.init(self.tname(t), c.transpose(NHWC_TO_NCHW) if nchw else c))
            else:
                names.append(self.get(t, layout))
        y = self.node("Concat", names, self.tname(out) + "_concat", axis=axis)
        return self.activation(y, o.FusedActivationFunction(), self.tname(out)), layout

    def op_unary(self, op, onnx_op):
        x = op.Inputs(0)
        name, layout = self.act[x]
        return self.node(onnx_op, [name], self.tname(op.Outputs(0))), layout

    def fold(self, op, kind):
        """Evaluate a constant op in numpy; True when done."""
        ins = [op.Inputs(k) for k in range(op.InputsLength())]
        if not all(t in self.const for t in ins):
            return False
        out = op.Outputs(0)
        if kind == "DENSIFY":
            sp = self.tensor(ins[0]).Sparsity()
            if sp is None:
                raise ConvertError("DENSIFY of a tensor without sparsity data")
            self.const[out] = densify(self.const[ins[0]], self.shape(out), sp)
        elif kind == "DEQUANTIZE":
            t = self.tensor(ins[0])
            arr = self.const[ins[0]]
            if t.Type() != TensorType.FLOAT16:  # int8/uint8 weights do not occur in these models
                raise ConvertError("DEQUANTIZE of type %d: only float16 is handled" % t.Type())
            self.const[out] = arr.astype(np.float32)
        else:
            return False
        return True

    # ---- graph ---------------------------------------------------------
    def prune(self, outputs):
        """Drop nodes and initializers that no kept output depends on."""
        have = [o.name for o in outputs]
        missing = [k for k in self.keep if k not in have]
        if missing:
            raise ConvertError("--outputs %s: no such output (have %s)" % (",".join(missing), ",".join(have)))
        need, nodes = set(self.keep), []
        for n in reversed(self.nodes):  # nodes are in topological order
            if any(o in need for o in n.output):
                nodes.append(n)
                need.update(n.input)
        self.nodes = nodes[::-1]
        self.inits = [t for t in self.inits if t.name in need]

    def convert(self):
        g = self.g
        inputs, outputs = [], []
        for k in range(g.OutputsLength()):  # reserved: intermediate nodes never take these names
            self.names.add(self.tname(g.Outputs(k)))
        for k in range(g.InputsLength()):
            t = g.Inputs(k)
            shp = self.shape(t)
            name = self.tname(t)
            self.names.add(name)
            if len(shp) == 4:  # NCHW in, what blobFromImage gives: the one input transpose
                inputs.append(helper.make_tensor_value_info(name, TensorProto.FLOAT,
                                                            [shp[i] for i in NHWC_TO_NCHW]))
                self.act[t] = (name, "nchw")
            else:
                inputs.append(helper.make_tensor_value_info(name, TensorProto.FLOAT, shp))
                self.act[t] = (name, "native")
        for i in range(g.OperatorsLength()):
            op = g.Operators(i)
            kind = opcode_name(self.model, op)
            opts = op.BuiltinOptions()
            try:
                if kind in ("DENSIFY", "DEQUANTIZE") and self.fold(op, kind):
                    continue
                if kind == "CONV_2D":
                    res = self.op_conv(op, opts, False)
                elif kind == "DEPTHWISE_CONV_2D":
                    res = self.op_conv(op, opts, True)
                elif kind == "PAD":
                    res = self.op_pad(op)
                    if res[0] is None:
                        continue
                elif kind == "ADD":
                    res = self.op_add_mul(op, opts, "Add")
                elif kind == "MUL":
                    res = self.op_add_mul(op, opts, "Mul")
                elif kind == "MAX_POOL_2D":
                    res = self.op_maxpool(op, opts)
                elif kind == "RESIZE_BILINEAR":
                    res = self.op_resize(op, opts)
                elif kind == "DEPTH_TO_SPACE":
                    res = self.op_depth_to_space(op, opts)
                elif kind == "RESHAPE":
                    res = self.op_reshape(op)
                elif kind == "CONCATENATION":
                    res = self.op_concat(op, opts)
                elif kind == "LOGISTIC":
                    res = self.op_unary(op, "Sigmoid")
                elif kind == "RELU":
                    res = self.op_unary(op, "Relu")
                elif kind == "TANH":
                    res = self.op_unary(op, "Tanh")
                else:
                    raise ConvertError("op not handled")
            except ConvertError as e:
                raise ConvertError("op %d %s (output %r): %s" % (i, kind, self.tname(op.Outputs(0)), e))
            self.act[op.Outputs(0)] = res
        for k in range(g.OutputsLength()):
            t = g.Outputs(k)
            name = self.tname(t)
            src = self.get(t, "native")  # TFLite's own layout and order
            producer = [n for n in self.nodes if src in n.output]
            used = any(src in n.input for n in self.nodes)
            if producer and not used:  # rename the last node's output to TFLite's name
                producer[0].output[0] = name
                producer[0].name = name
            else:
                self.nodes.append(helper.make_node("Identity", [src], [name], name=name))
            outputs.append(helper.make_tensor_value_info(name, TensorProto.FLOAT, self.shape(t)))
        if self.keep is not None:
            self.prune(outputs)
            outputs = [o for o in outputs if o.name in self.keep]
        graph = helper.make_graph(self.nodes, "blazepose", inputs, outputs, self.inits)
        model = helper.make_model(graph, producer_name="gravscale-tflite_onnx",
                                  opset_imports=[helper.make_opsetid("", OPSET)])
        model.ir_version = 7  # what OpenCV 4.6's bundled onnx proto and opset 11 expect
        return model


def convert_file(src, dst, strict_clip=False, keep=None):
    with open(src, "rb") as f:
        buf = f.read()
    if buf[4:8] != b"TFL3":
        raise ConvertError("not a TFLite flatbuffer (identifier %r, want 'TFL3')" % buf[4:8])
    try:
        model = Converter(buf, strict_clip, keep).convert()
    except ConvertError:
        raise
    except Exception as e:  # a damaged flatbuffer surfaces as any error of the tflite reader
        raise ConvertError("damaged TFLite file (%s: %s)" % (type(e).__name__, e))
    data = model.SerializeToString(deterministic=True)
    with open(dst, "wb") as f:
        f.write(data)
    return model


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("src")
    ap.add_argument("dst", nargs="?")
    ap.add_argument("--strict-clip", action="store_true",
                    help="spec-valid opset-11 Clip with min/max inputs (onnx.checker; not OpenCV 4.6)")
    ap.add_argument("--outputs", help="comma-separated output names to keep (default: all)")
    ap.add_argument("--list-ops", action="store_true", help="print the TFLite ops used and exit")
    a = ap.parse_args(argv)
    try:
        if a.list_ops:
            with open(a.src, "rb") as f:
                m = tflite.Model.GetRootAsModel(f.read(), 0)
            for k, v in list_ops(m).items():
                print("%-20s %d" % (k, v))
            return 0
        if not a.dst:
            ap.error("need OUT.onnx")
        keep = a.outputs.split(",") if a.outputs else None
        convert_file(a.src, a.dst, a.strict_clip, keep)
    except (ConvertError, OSError) as e:
        print("tflite_onnx: %s: %s" % (a.src, e), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
