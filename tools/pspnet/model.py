"""Compact PSPNet (paper Fig. 2) on a dilated MobileNetV2 backbone.

Backbone: MobileNetV2 with the strides of the last stages replaced by dilation
(64/96-channel stages: dilation 2, 160/320-channel stages: dilation 4, or 2 with
last_dilation=2 as shipped), so the final feature map is 1/8 of the input.  The backbone convolutions carry
a bias and no batch-norm: the pretrained DeepLab v3 weights we start from have
batch-norm folded into the convolutions already, so conv+bias reproduces them
exactly and fine-tuning does not depend on small-batch statistics.

Head: pyramid pooling module (average pooling to 1x1, 2x2, 3x3, 6x6 bins, each
followed by 1x1 conv + BN + ReLU and bilinear upsampling), concatenated with the
backbone features, 3x3 conv + BN + ReLU + dropout, 1x1 classifier to 21 VOC
classes, bilinear upsampling of the logits to the input size inside the graph.
"""

import torch
import torch.nn as nn
import torch.nn.functional as F

NUM_CLASSES = 21
PERSON = 15

# (expansion t, output channels c, repeats n, stride s, dilation d) per stage.
# Original MobileNetV2 strides are 1,2,2,2,1,2,1; the last two stride-2 stages
# become stride 1 with dilation so that the output stride is 8.
STAGES = [
    (1, 16, 1, 1, 1),
    (6, 24, 2, 2, 1),
    (6, 32, 3, 2, 1),
    (6, 64, 4, 1, 2),
    (6, 96, 3, 1, 2),
    (6, 160, 3, 1, 4),
    (6, 320, 1, 1, 4),
]
# Channel widths (stem, then one per stage) of MobileNetV2 1.0 and of the
# depth-multiplier-0.5 variant used by deeplabv3_mnv2_dm05_pascal.onnx.
WIDTHS = {
    "1.0": (32, 16, 24, 32, 64, 96, 160, 320),
    "0.5": (16, 8, 12, 16, 32, 48, 80, 160),
}


def conv_relu6(cin, cout, k, stride=1, dilation=1, groups=1):
    pad = dilation * (k // 2)
    return nn.Sequential(
        nn.Conv2d(cin, cout, k, stride, pad, dilation=dilation, groups=groups, bias=True),
        nn.ReLU6(inplace=True))


class InvertedResidual(nn.Module):
    def __init__(self, cin, cout, expand, stride, dilation):
        super().__init__()
        hidden = cin * expand
        layers = []
        if expand != 1:
            layers.append(conv_relu6(cin, hidden, 1))
        layers.append(conv_relu6(hidden, hidden, 3, stride, dilation, groups=hidden))
        layers.append(nn.Conv2d(hidden, cout, 1, bias=True))  # linear bottleneck
        self.body = nn.Sequential(*layers)
        self.residual = stride == 1 and cin == cout

        self.dilation = dilation

    def forward(self, x, phase_layout=False):
        """phase_layout: x holds the dilation-rate phases of the feature map as
        batch entries (space-to-batch), so the depthwise conv runs undilated."""
        if not phase_layout or self.dilation == 1:
            y = self.body(x)
        else:
            expand, depthwise, project = self.body[:-2], self.body[-2], self.body[-1]
            conv = depthwise[0]
            # depthwise[1] (nn.ReLU6) exports as one Clip(0, 6), which OpenCV fuses into the
            # convolution; F.relu6 exports as Relu + Clip, a separate pass over the tensor.
            y = depthwise[1](F.conv2d(expand(x), conv.weight, conv.bias, conv.stride, 1, 1,
                                      conv.groups))
            y = project(y)
        return x + y if self.residual else y


def space_to_batch(x, rate):
    """(1, C, H, W) -> (rate*rate, C, H/rate, W/rate): batch entry (py, px) holds pixels
    (py + rate*i, px + rate*j).  A 3x3 convolution with dilation `rate` on x equals an
    undilated 3x3 convolution on each entry, zero padding included.  Written as one 4-D
    permute (channel and phase row stay adjacent): OpenCV 4.6 permutes 4-D tensors with a
    parallel strided copy but 5-D/6-D ones element by element (12 ms for the 160-channel
    merge at 288x240 vs <1 ms)."""
    _, c, h, w = x.shape
    x = x.reshape(c * (h // rate), rate, w // rate, rate)  # (c i, py, j, px)
    return x.permute(1, 3, 0, 2).reshape(rate * rate, c, h // rate, w // rate)


def batch_to_space(x, rate):
    """Inverse of space_to_batch."""
    _, c, h, w = x.shape
    x = x.reshape(rate, rate, c * h, w)  # (py, px, c i, j)
    return x.permute(2, 0, 3, 1).reshape(1, c, h * rate, w * rate)


class DilatedMobileNetV2(nn.Module):
    """MobileNetV2 with output stride 8: stages 64/96 dilated by 2, 160/320 by 4.

    (We tried running the dilated stages in a space-to-batch layout, which is
    exact, to avoid OpenCV 4.6's slow dilated depthwise path; the 6-D
    transposes cost more in OpenCV than they saved, so plain dilation it is.)
    """

    def __init__(self, width="1.0", last_dilation=4):
        super().__init__()
        widths = WIDTHS[width]
        self.out_channels = widths[-1]
        layers = [conv_relu6(3, widths[0], 3, stride=2)]
        cin = widths[0]
        for (t, _, n, s, d), c in zip(STAGES, widths[1:]):
            d = last_dilation if d == 4 else d
            for i in range(n):
                layers.append(InvertedResidual(cin, c, t, s if i == 0 else 1, d))
                cin = c
        self.features = nn.Sequential(*layers)

        # Export switch: run the dilated stages in space-to-batch layout, converting once
        # per change of dilation rate (OpenCV 4.6 has a fast path for undilated 3x3
        # depthwise convolutions only; dilated ones cost ~6x more).
        self.phase_layout = False

    def forward(self, x):
        if not self.phase_layout:
            return self.features(x)
        rate = 1  # dilation rate of the phase split x is in
        for layer in self.features:
            d = layer.dilation if isinstance(layer, InvertedResidual) else 1
            if d != rate:
                x = batch_to_space(x, rate) if rate > 1 else x
                x = space_to_batch(x, d) if d > 1 else x
                rate = d
            x = layer(x, True) if isinstance(layer, InvertedResidual) else layer(x)
        return batch_to_space(x, rate) if rate > 1 else x

    def phase_layout_pays(self, feat_hw):
        """OpenCV 4.6's fast 3x3 depthwise path needs rows of >= 18 outputs (measured:
        18 and 24 fast, 16 and 12 slow); only then is the phase layout worth its two
        transposes.  One dilation rate only, dividing the feature map."""
        rates = {m.dilation for m in self.features if isinstance(m, InvertedResidual)} - {1}
        if len(rates) != 1:
            return False
        rate = rates.pop()
        h, w = feat_hw
        return h % rate == 0 and w % rate == 0 and w // rate >= 18

    def convs(self):
        """All Conv2d layers in graph order (matches the DeepLab ONNX order)."""
        return [m for m in self.features.modules() if isinstance(m, nn.Conv2d)]


class PyramidPooling(nn.Module):
    """PPM with bins 1, 2, 3, 6.

    The bins are written as fixed-kernel average pooling (kernel = stride =
    feature size / bins), which is what adaptive pooling equals when the
    feature size divides by the bin count; it exports to ONNX AveragePool that
    OpenCV 4.6 reads.  The feature size is therefore fixed at construction.
    """

    def __init__(self, cin, branch_channels, feat_hw, bins=(1, 2, 3, 6)):
        super().__init__()
        fh, fw = feat_hw
        for b in bins:
            if fh % b or fw % b:
                raise ValueError(f"feature map {fw}x{fh} does not divide by bin {b}")
        self.bins = bins
        self.kernels = [(fh // b, fw // b) for b in bins]
        self.branches = nn.ModuleList([
            nn.Sequential(nn.Conv2d(cin, branch_channels, 1, bias=False),
                          nn.BatchNorm2d(branch_channels), nn.ReLU(inplace=True))
            for _ in bins])

    def forward(self, x):
        size = x.shape[-2:]
        outs = [x]
        for k, branch in zip(self.kernels, self.branches):
            y = F.avg_pool2d(x, kernel_size=k, stride=k)
            y = branch(y)
            outs.append(F.interpolate(y, size=size, mode="bilinear", align_corners=False))
        return torch.cat(outs, 1)


class PSPNet(nn.Module):
    # Defaults = the shipped model (width 0.5, 4 x 32 pyramid channels, 64 head channels).
    def __init__(self, input_hw=(288, 384), width="0.5", branch_channels=32,
                 head_channels=64, num_classes=NUM_CLASSES, dropout=0.1, last_dilation=4):
        super().__init__()
        h, w = input_hw
        if h % 8 or w % 8:
            raise ValueError("input size must divide by 8")
        self.input_hw = input_hw
        self.backbone = DilatedMobileNetV2(width, last_dilation)
        cin = self.backbone.out_channels
        self.ppm = PyramidPooling(cin, branch_channels, (h // 8, w // 8))
        self.head = nn.Sequential(
            nn.Conv2d(cin + 4 * branch_channels, head_channels, 3, padding=1, bias=False),
            nn.BatchNorm2d(head_channels), nn.ReLU(inplace=True), nn.Dropout2d(dropout),
            nn.Conv2d(head_channels, num_classes, 1))

    def forward(self, x):
        size = x.shape[-2:]
        y = self.head(self.ppm(self.backbone(x)))
        return F.interpolate(y, size=size, mode="bilinear", align_corners=False)

    def param_groups(self):
        backbone = list(self.backbone.parameters())
        ids = {id(p) for p in backbone}
        head = [p for p in self.parameters() if id(p) not in ids]
        return backbone, head
