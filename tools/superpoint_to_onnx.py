#!/usr/bin/python3
"""Converts a SuperPointNet state_dict (MagicLeap's superpoint_v1.pth, or your own training of the same network)
to the ONNX interface Drover's SuperPointDetector reads (src/visual/superpoint_detector.hpp):

    input  `input` 1x1xHxW float32, grey scaled to [0, 1], H and W dynamic (multiples of 8)
    output `semi`  1x65xH/8xW/8  detector logits (64 pixels of an 8x8 cell + dustbin), no softmax
    output `desc`  1x256xH/8xW/8 coarse descriptors, NOT normalised (Drover normalises after sampling)

The network is SuperPointNet of DeTone, Malisiewicz & Rabinovich, "SuperPoint: Self-Supervised Interest Point
Detection and Description" (CVPRW 2018), with the layer names of MagicLeap's demo_superpoint.py (conv1a, conv1b,
conv2a, conv2b, conv3a, conv3b, conv4a, conv4b, convPa, convPb, convDa, convDb), written here from the paper's
description; the state_dict must have exactly these keys (a `module.` prefix from DataParallel is stripped).

Requirements: Debian's python3-torch (apt-get install python3-torch; heavy, so NOT in scripts/install_deps.sh) and
python3-onnx. Run with /usr/bin/python3 (Debian's modules).

Usage:
    /usr/bin/python3 tools/superpoint_to_onnx.py superpoint_v1.pth superpoint_v1.onnx [--opset 11]
then point Drover at it: `drover features detect --weights superpoint_v1.onnx ...` or the config key
visual.detector.superpoint.weights.

Checked here (python3-torch installed by hand, not in CI): a state_dict rebuilt from the tensors of
../shared/models/superpoint_v1.onnx, converted by this script, gives the same keypoints (count and coverage) as the
shared file on a KITTI and a EuRoC frame (`drover features detect --weights ...`).

Licence: MagicLeap's pretrained weights are for non-commercial research use only; converting them does not change
that. Weights you trained yourself are yours.
"""
import argparse
import sys

try:
    import torch
except ImportError:
    sys.exit("superpoint_to_onnx: python3-torch is not installed (apt-get install python3-torch); run with "
             "/usr/bin/python3")

LAYERS = ["conv1a", "conv1b", "conv2a", "conv2b", "conv3a", "conv3b", "conv4a", "conv4b",
          "convPa", "convPb", "convDa", "convDb"]


class SuperPointNet(torch.nn.Module):
    """Shared VGG-style encoder (8x downsampling) and two heads; the heads are returned raw."""

    def __init__(self):
        super().__init__()
        c1, c2, c3, c4, c5, d1 = 64, 64, 128, 128, 256, 256
        conv = torch.nn.Conv2d
        self.relu = torch.nn.ReLU(inplace=True)
        self.pool = torch.nn.MaxPool2d(kernel_size=2, stride=2)
        self.conv1a = conv(1, c1, kernel_size=3, stride=1, padding=1)
        self.conv1b = conv(c1, c1, kernel_size=3, stride=1, padding=1)
        self.conv2a = conv(c1, c2, kernel_size=3, stride=1, padding=1)
        self.conv2b = conv(c2, c2, kernel_size=3, stride=1, padding=1)
        self.conv3a = conv(c2, c3, kernel_size=3, stride=1, padding=1)
        self.conv3b = conv(c3, c3, kernel_size=3, stride=1, padding=1)
        self.conv4a = conv(c3, c4, kernel_size=3, stride=1, padding=1)
        self.conv4b = conv(c4, c4, kernel_size=3, stride=1, padding=1)
        self.convPa = conv(c4, c5, kernel_size=3, stride=1, padding=1)
        self.convPb = conv(c5, 65, kernel_size=1, stride=1, padding=0)
        self.convDa = conv(c4, c5, kernel_size=3, stride=1, padding=1)
        self.convDb = conv(c5, d1, kernel_size=1, stride=1, padding=0)

    def forward(self, x):
        r = self.relu
        x = self.pool(r(self.conv1b(r(self.conv1a(x)))))
        x = self.pool(r(self.conv2b(r(self.conv2a(x)))))
        x = self.pool(r(self.conv3b(r(self.conv3a(x)))))
        x = r(self.conv4b(r(self.conv4a(x))))
        semi = self.convPb(r(self.convPa(x)))
        desc = self.convDb(r(self.convDa(x)))
        return semi, desc


def load_state_dict(path):
    try:
        sd = torch.load(path, map_location="cpu")
    except Exception as e:  # pickle, zip and IO errors alike: one clear line
        sys.exit("superpoint_to_onnx: %s is not a readable PyTorch file (%s: %s)" % (path, type(e).__name__, e))
    if isinstance(sd, dict) and "state_dict" in sd and isinstance(sd["state_dict"], dict):
        sd = sd["state_dict"]  # a training checkpoint
    if not isinstance(sd, dict):
        sys.exit("superpoint_to_onnx: %s does not hold a state_dict (got %s)" % (path, type(sd).__name__))
    sd = {k[len("module."):] if k.startswith("module.") else k: v for k, v in sd.items()}
    expected = {"%s.%s" % (l, p) for l in LAYERS for p in ("weight", "bias")}
    missing, extra = expected - set(sd), set(sd) - expected
    if missing or extra:
        sys.exit("superpoint_to_onnx: %s is not a SuperPointNet state_dict (missing %s, unexpected %s)"
                 % (path, sorted(missing), sorted(extra)))
    return sd


def main():
    ap = argparse.ArgumentParser(description="SuperPointNet state_dict (.pth) -> Drover's SuperPoint ONNX")
    ap.add_argument("pth")
    ap.add_argument("onnx")
    ap.add_argument("--opset", type=int, default=11)
    a = ap.parse_args()
    net = SuperPointNet()
    net.load_state_dict(load_state_dict(a.pth), strict=True)  # also checks every tensor's shape
    net.eval()
    dummy = torch.rand(1, 1, 120, 160)
    with torch.no_grad():
        semi, desc = net(dummy)
        torch.onnx.export(net, dummy, a.onnx, opset_version=a.opset, input_names=["input"],
                          output_names=["semi", "desc"],
                          dynamic_axes={"input": {2: "H", 3: "W"}, "semi": {2: "Hc", 3: "Wc"},
                                        "desc": {2: "Hc", 3: "Wc"}})
    try:
        import onnx
        onnx.checker.check_model(onnx.load(a.onnx))
    except ImportError:
        print("superpoint_to_onnx: python3-onnx not installed; the file was written but not checked")
    print("wrote %s: semi %s, desc %s for a 1x1x120x160 input (opset %d)"
          % (a.onnx, tuple(semi.shape), tuple(desc.shape), a.opset))


if __name__ == "__main__":
    main()
