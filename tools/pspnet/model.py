"""Compact PSPNet (paper Fig. 2) on a dilated MobileNetV2 backbone.

Backbone: MobileNetV2 whose strides past the output stride are replaced by dilation:
output stride 16 (shipped: the 160/320-channel stages dilated by 2, as DeepLab v3 runs the
MobileNetV2 it is initialised from) or 8 (the 64/96-channel stages dilated by 2 too, the
160/320 ones by `last_dilation`).  The backbone convolutions carry a bias and no
batch-norm: the pretrained DeepLab v3 weights we start from have batch-norm folded into
the convolutions already, so conv+bias reproduces them exactly and fine-tuning does not
depend on small-batch statistics.

Head: pyramid pooling module (average pooling to 1x1, 2x2, 3x3, 6x6 bins, each
followed by 1x1 conv + BN + ReLU and bilinear upsampling), concatenated with the
backbone features, a 3x3 conv (or, `separable_head`, a depthwise 3x3 + 1x1 conv) + BN +
ReLU + dropout; optionally (`decoder_channels` > 0) a light decoder that upsamples the
head's features to 1/4 of the input and refines them with the backbone's 1/4 features
(DeepLab v3+'s idea: the coarse map knows *what*, the early features *where* the edges
are); a 1x1 classifier to 21 VOC classes, bilinear upsampling of the logits to the input
size inside the graph.
"""

import torch
import torch.nn as nn
import torch.nn.functional as F

NUM_CLASSES = 21
PERSON = 15

# (expansion t, output channels c, repeats n, stride s) per stage: MobileNetV2's own strides.
# A stride that would take the map below the output stride becomes stride 1, and the
# stage and all after it are dilated by the stride they gave up (see stage_plan).
STAGES = [
    (1, 16, 1, 1),
    (6, 24, 2, 2),
    (6, 32, 3, 2),
    (6, 64, 4, 2),
    (6, 96, 3, 1),
    (6, 160, 3, 2),
    (6, 320, 1, 1),
]
# Index into `DilatedMobileNetV2.features` after which the map is at 1/4 of the input
# (stem, the 16 stage's block, the 24 stage's two blocks): the decoder's early features.
QUARTER_FEATURES_END = 4
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


def stage_plan(output_stride, last_dilation):
    """(stride, dilation) of each stage for the given output stride (8 or 16).
    The 160/320 stages, whose stride the output stride drops in both cases, are dilated by
    `last_dilation` (2 as DeepLab v3 runs them; 1 drops the dilation: cheaper in OpenCV 4.6,
    whose dilated depthwise convolutions are ~6x slower than undilated ones); output stride
    8 also drops the 64 stage's stride and dilates the 64/96 stages by 2."""
    if output_stride not in (8, 16):
        raise ValueError("output stride must be 8 or 16")
    plan, reached, rate = [], 2, 1  # the stem halves the input
    for _, c, _, s in STAGES:
        if s > 1 and reached * s > output_stride:
            rate = last_dilation if c == 160 else 2
            s = 1
        reached *= s
        plan.append((s, rate))
    return plan


class DilatedMobileNetV2(nn.Module):
    """MobileNetV2 with output stride 8 or 16 (see stage_plan)."""

    def __init__(self, width="1.0", last_dilation=4, output_stride=8):
        super().__init__()
        widths = WIDTHS[width]
        self.out_channels = widths[-1]
        self.quarter_channels = widths[2]
        layers = [conv_relu6(3, widths[0], 3, stride=2)]
        cin = widths[0]
        plan = stage_plan(output_stride, last_dilation)
        for (t, _, n, _), (s, d), c in zip(STAGES, plan, widths[1:]):
            for i in range(n):
                layers.append(InvertedResidual(cin, c, t, s if i == 0 else 1, d))
                cin = c
        self.features = nn.Sequential(*layers)

        # Export switch: run the dilated stages in space-to-batch layout, converting once
        # per change of dilation rate (OpenCV 4.6 has a fast path for undilated 3x3
        # depthwise convolutions only; dilated ones cost ~6x more).
        self.phase_layout = False

    def forward(self, x):
        """Returns (features at the output stride, features at 1/4 of the input)."""
        quarter = self.features[:QUARTER_FEATURES_END](x)
        rest = self.features[QUARTER_FEATURES_END:]
        if not self.phase_layout:
            return rest(quarter), quarter
        x = quarter
        rate = 1  # dilation rate of the phase split x is in
        for layer in rest:
            d = layer.dilation if isinstance(layer, InvertedResidual) else 1
            if d != rate:
                x = batch_to_space(x, rate) if rate > 1 else x
                x = space_to_batch(x, d) if d > 1 else x
                rate = d
            x = layer(x, True) if isinstance(layer, InvertedResidual) else layer(x)
        return (batch_to_space(x, rate) if rate > 1 else x), quarter

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


def conv_bn_relu(cin, cout, k=1, groups=1):
    return [nn.Conv2d(cin, cout, k, padding=k // 2, groups=groups, bias=False),
            nn.BatchNorm2d(cout), nn.ReLU(inplace=True)]


class PSPNet(nn.Module):
    # Defaults = the shipped model (see MODEL_CARD.md): width 0.5, output stride 16,
    # 4 x 32 pyramid channels, a separable 64-channel head and a 48-channel 1/4 decoder.
    def __init__(self, input_hw=(288, 384), width="0.5", branch_channels=32,
                 head_channels=64, num_classes=NUM_CLASSES, dropout=0.1, last_dilation=2,
                 output_stride=16, separable_head=True, decoder_channels=48):
        super().__init__()
        h, w = input_hw
        if h % output_stride or w % output_stride:
            raise ValueError(f"input size must divide by the output stride {output_stride}")
        self.input_hw = input_hw
        self.backbone = DilatedMobileNetV2(width, last_dilation, output_stride)
        cin = self.backbone.out_channels
        self.ppm = PyramidPooling(cin, branch_channels, (h // output_stride, w // output_stride))
        concat = cin + 4 * branch_channels
        if separable_head:
            # A dense 3x3 over the 288 concatenated channels was the slowest layer of the
            # first model (20 ms of ~66 in OpenCV); depthwise + pointwise is ~9x cheaper.
            head = conv_bn_relu(concat, concat, 3, groups=concat)[:2] + conv_bn_relu(
                concat, head_channels)
        else:
            head = conv_bn_relu(concat, head_channels, 3)
        self.head = nn.Sequential(*head, nn.Dropout2d(dropout))
        self.decoder = None
        classifier_in = head_channels
        if decoder_channels > 0:
            early = 16
            self.early = nn.Sequential(*conv_bn_relu(self.backbone.quarter_channels, early))
            both = head_channels + early
            self.decoder = nn.Sequential(*conv_bn_relu(both, both, 3, groups=both)[:2],
                                         *conv_bn_relu(both, decoder_channels))
            classifier_in = decoder_channels
        self.classifier = nn.Conv2d(classifier_in, num_classes, 1)

    def forward(self, x):
        size = x.shape[-2:]
        deep, quarter = self.backbone(x)
        y = self.head(self.ppm(deep))
        if self.decoder is not None:
            y = F.interpolate(y, size=quarter.shape[-2:], mode="bilinear", align_corners=False)
            y = self.decoder(torch.cat([y, self.early(quarter)], 1))
        y = self.classifier(y)
        return F.interpolate(y, size=size, mode="bilinear", align_corners=False)

    def param_groups(self):
        backbone = list(self.backbone.parameters())
        ids = {id(p) for p in backbone}
        head = [p for p in self.parameters() if id(p) not in ids]
        return backbone, head


# The architectures trained and compared in MODEL_CARD.md, by name (train.py --arch).
ARCHITECTURES = {
    # output stride 16 with the 1/4 decoder
    "os16_decoder": dict(output_stride=16, separable_head=True, decoder_channels=48),
    # the first model's layout (output stride 8, dense 3x3 head), for comparison
    "os8": dict(output_stride=8, separable_head=False, decoder_channels=0),
}
