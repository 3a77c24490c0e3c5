#!/usr/bin/python3
"""Builds a SuperPoint-ARCHITECTURE ONNX with fixed, seeded random weights and computes what SuperPointDetector must
return on a synthetic test image, with numpy only (no ONNX runtime), for tests/visual/test_superpoint.cpp.

The layers are SuperPointNet's (DeTone et al. 2018; MagicLeap's demo_superpoint.py): a VGG encoder
conv1a,conv1b | pool | conv2a,conv2b | pool | conv3a,conv3b | pool | conv4a,conv4b (3x3, ReLU), a detector head
convPa (3x3, 256, ReLU) -> convPb (1x1, 65) and a descriptor head convDa (3x3, 256, ReLU) -> convDb (1x1, 256).
Input `input` 1x1xHxW float32 in [0, 1]; outputs `semi` 1x65xH/8xW/8 and `desc` 1x256xH/8xW/8 (raw heads).

The reference post-processing below is written from the paper and the demo, not from the C++: a dense softmax and
a reshape-based depth-to-space, a greedy NMS that compares each candidate with the kept list (vectorised
Chebyshev distances), border removal, top-k, and vectorised bilinear descriptor sampling.

Usage: make_superpoint_onnx.py OUT_DIR [--variant ok|semi64|no-desc]
Writes OUT_DIR/model.onnx, and for the `ok` variant image.u8 (H*W bytes, row-major), meta.txt ("H W N MAX"),
points.f32 (N x 2: x, y), scores.f32 (N), desc.f32 (N x 256), all little-endian float32.
Needs Debian's python3-onnx and python3-numpy; exits 77 when onnx is missing (the test then skips).
"""
import argparse
import os
import sys

import numpy as np

try:
    import onnx
    from onnx import TensorProto, helper, numpy_helper
except ImportError:
    print("python3-onnx is not installed (apt-get install python3-onnx)", file=sys.stderr)
    sys.exit(77)

H, W = 96, 128            # test image [px], multiples of 8
THRESHOLD, NMS_RADIUS, BORDER, MAX_COUNT = 0.015, 4, 4, 1000
SEED = 3
LOGIT_STD = 3.0           # convPb is scaled so the logits spread: few probabilities sit near the threshold

# name, in, out, kernel, relu
ENCODER = [("conv1a", 1, 64), ("conv1b", 64, 64), "pool", ("conv2a", 64, 64), ("conv2b", 64, 64), "pool",
           ("conv3a", 64, 128), ("conv3b", 128, 128), "pool", ("conv4a", 128, 128), ("conv4b", 128, 128)]


def conv(x, w, b):
    """Cross-correlation with 'same' zero padding, as ONNX Conv: x (C,H,W), w (O,C,k,k)."""
    k = w.shape[2]
    p = k // 2
    c, h, wd = x.shape
    xp = np.pad(x, ((0, 0), (p, p), (p, p)))
    cols = np.stack([xp[:, i:i + h, j:j + wd] for i in range(k) for j in range(k)], axis=1)
    return (w.reshape(w.shape[0], -1) @ cols.reshape(c * k * k, h * wd)).reshape(-1, h, wd) + b[:, None, None]


def pool(x):
    c, h, w = x.shape
    return x.reshape(c, h // 2, 2, w // 2, 2).max(axis=(2, 4))


def make_weights(rng, variant):
    weights = {}
    for layer in ENCODER:
        if layer == "pool":
            continue
        name, cin, cout = layer
        weights[name] = (rng.normal(0, np.sqrt(2.0 / (cin * 9)), (cout, cin, 3, 3)), rng.normal(0, 0.01, cout))
    pb_out = 64 if variant == "semi64" else 65
    weights["convPa"] = (rng.normal(0, np.sqrt(2.0 / (128 * 9)), (256, 128, 3, 3)), rng.normal(0, 0.01, 256))
    weights["convPb"] = (rng.normal(0, np.sqrt(1.0 / 256), (pb_out, 256, 1, 1)), rng.normal(0, 0.5, pb_out))
    weights["convDa"] = (rng.normal(0, np.sqrt(2.0 / (128 * 9)), (256, 128, 3, 3)), rng.normal(0, 0.01, 256))
    weights["convDb"] = (rng.normal(0, np.sqrt(1.0 / 256), (256, 256, 1, 1)), rng.normal(0, 0.01, 256))
    # float32, as stored in the ONNX file; the forward pass below then runs in float64 on the same values
    return {k: (w.astype(np.float32), b.astype(np.float32)) for k, (w, b) in weights.items()}


def forward(weights, img):
    x = img[None].astype(np.float64)
    for layer in ENCODER:
        x = pool(x) if layer == "pool" else np.maximum(conv(x, *weights[layer[0]]), 0)
    pa = np.maximum(conv(x, *weights["convPa"]), 0)
    da = np.maximum(conv(x, *weights["convDa"]), 0)
    return pa, conv(pa, *weights["convPb"]), conv(da, *weights["convDb"])


def build_onnx(weights, variant, path):
    nodes, inits, x = [], [], "input"
    def add_conv(name, src, relu):
        w, b = weights[name]
        inits.extend([numpy_helper.from_array(w, name + ".weight"), numpy_helper.from_array(b, name + ".bias")])
        k = w.shape[2]
        out = name + "_out"
        nodes.append(helper.make_node("Conv", [src, name + ".weight", name + ".bias"], [out], kernel_shape=[k, k],
                                      pads=[k // 2] * 4))
        if relu:
            nodes.append(helper.make_node("Relu", [out], [name + "_relu"]))
            out = name + "_relu"
        return out
    for i, layer in enumerate(ENCODER):
        if layer == "pool":
            nodes.append(helper.make_node("MaxPool", [x], ["pool%d" % i], kernel_shape=[2, 2], strides=[2, 2]))
            x = "pool%d" % i
        else:
            x = add_conv(layer[0], x, True)
    pa = add_conv("convPa", x, True)
    pb = add_conv("convPb", pa, False)
    nodes.append(helper.make_node("Identity", [pb], ["semi"]))
    outputs = [helper.make_tensor_value_info("semi", TensorProto.FLOAT, [1, weights["convPb"][0].shape[0], "Hc", "Wc"])]
    if variant != "no-desc":
        da = add_conv("convDa", x, True)
        db = add_conv("convDb", da, False)
        nodes.append(helper.make_node("Identity", [db], ["desc"]))
        outputs.append(helper.make_tensor_value_info("desc", TensorProto.FLOAT, [1, 256, "Hc", "Wc"]))
    graph = helper.make_graph(nodes, "superpoint_test", [helper.make_tensor_value_info(
        "input", TensorProto.FLOAT, [1, 1, "H", "W"])], outputs, inits)
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 11)], producer_name="drover-test")
    onnx.checker.check_model(model)
    onnx.save(model, path)


def test_image(rng):
    """Shapes with corners on a smooth gradient plus mild noise: a few dozen keypoints."""
    yy, xx = np.mgrid[0:H, 0:W]
    img = 40 + 0.6 * xx + 0.3 * yy
    img[20:50, 15:45] = 200
    img[60:85, 70:110] = 20
    img[((yy - 30) ** 2 + (xx - 90) ** 2) < 12 ** 2] = 230
    img[10:30, 55:60] = 120
    img = img + rng.normal(0, 3, img.shape)
    return np.clip(np.round(img), 0, 255).astype(np.uint8)


def postprocess(semi, desc):
    e = np.exp(semi - semi.max(axis=0, keepdims=True))
    prob = (e / e.sum(axis=0, keepdims=True))[:-1]            # drop the dustbin
    hc, wc = prob.shape[1:]
    heat = prob.transpose(1, 2, 0).reshape(hc, wc, 8, 8).transpose(0, 2, 1, 3).reshape(hc * 8, wc * 8)
    near = np.abs(heat - THRESHOLD) < 1e-5
    if near.any():
        sys.exit("reference: %d probabilities within 1e-5 of the threshold; choose another SEED" % near.sum())
    ys, xs = np.nonzero(heat >= THRESHOLD)
    sc = heat[ys, xs]
    order = np.lexsort((xs, ys, -sc))
    kx, ky, ks = np.empty(0, int), np.empty(0, int), np.empty(0)
    for i in order:
        close = np.maximum(np.abs(kx - xs[i]), np.abs(ky - ys[i])) <= NMS_RADIUS
        if close.any():
            if np.min(np.abs(ks[close] - sc[i]) / sc[i]) < 1e-5:
                sys.exit("reference: near tie in NMS; choose another SEED")
            continue
        kx, ky, ks = np.append(kx, xs[i]), np.append(ky, ys[i]), np.append(ks, sc[i])
    inside = (kx >= BORDER) & (kx < wc * 8 - BORDER) & (ky >= BORDER) & (ky < hc * 8 - BORDER)
    kx, ky, ks = kx[inside][:MAX_COUNT], ky[inside][:MAX_COUNT], ks[inside][:MAX_COUNT]
    coarse = desc / np.linalg.norm(desc, axis=0, keepdims=True)
    u = np.clip((kx - 3.5) / 8, 0, wc - 1)
    v = np.clip((ky - 3.5) / 8, 0, hc - 1)
    u0, v0 = np.floor(u).astype(int), np.floor(v).astype(int)
    u1, v1 = np.minimum(u0 + 1, wc - 1), np.minimum(v0 + 1, hc - 1)
    fu, fv = u - u0, v - v0
    d = (coarse[:, v0, u0] * (1 - fu) * (1 - fv) + coarse[:, v0, u1] * fu * (1 - fv) +
         coarse[:, v1, u0] * (1 - fu) * fv + coarse[:, v1, u1] * fu * fv).T
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return np.stack([kx, ky], axis=1), ks, d


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out_dir")
    ap.add_argument("--variant", choices=["ok", "semi64", "no-desc"], default="ok")
    a = ap.parse_args()
    os.makedirs(a.out_dir, exist_ok=True)
    rng = np.random.default_rng(SEED)
    weights = make_weights(rng, a.variant)
    img = test_image(rng)
    pa, semi, desc = forward(weights, img / 255.0)
    # Scale the detector head so its logits have standard deviation LOGIT_STD (baked into the float32 weights).
    s = LOGIT_STD / semi.std()
    weights["convPb"] = ((weights["convPb"][0] * s).astype(np.float32), (weights["convPb"][1] * s).astype(np.float32))
    build_onnx(weights, a.variant, os.path.join(a.out_dir, "model.onnx"))
    if a.variant != "ok":
        return
    semi = conv(pa, *weights["convPb"])
    pts, scores, d = postprocess(semi, desc)
    img.tofile(os.path.join(a.out_dir, "image.u8"))
    pts.astype("<f4").tofile(os.path.join(a.out_dir, "points.f32"))
    scores.astype("<f4").tofile(os.path.join(a.out_dir, "scores.f32"))
    d.astype("<f4").tofile(os.path.join(a.out_dir, "desc.f32"))
    with open(os.path.join(a.out_dir, "meta.txt"), "w") as f:
        f.write("%d %d %d %d\n" % (H, W, len(scores), MAX_COUNT))
    print("reference: %d keypoints, scores %.4f..%.4f" % (len(scores), scores.min(), scores.max()))


if __name__ == "__main__":
    main()
