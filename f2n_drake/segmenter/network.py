"""DeepLabV3+ on a slim MobileNetV2 encoder, in plain torch.

DeepLabV3+: L.-C. Chen, Y. Zhu, G. Papandreou, F. Schroff, H. Adam, "Encoder-Decoder with Atrous
Separable Convolution for Semantic Image Segmentation", ECCV 2018 (arXiv:1802.02611).
Encoder: M. Sandler et al., "MobileNetV2: Inverted Residuals and Linear Bottlenecks", CVPR 2018
(arXiv:1801.04381), one of the encoders the DeepLabV3+ paper itself evaluates.

The encoder's last stride-2 stages become dilated stride-1 stages so features stop at output
stride 16 (or 8); ASPP runs there; the decoder fuses the upsampled ASPP features with 1/4
resolution low-level features. ASPP branches and decoder convolutions are depthwise separable,
as in the paper ("atrous separable convolution"), which keeps a 512x512 forward pass cheap on CPU.
"""

from __future__ import annotations

import copy
from typing import Literal

import torch
import torch.nn.functional as F
from torch import nn
from torch.nn.utils.fusion import fuse_conv_bn_eval

# MobileNetV2 stages: (expansion t, channels c at width 1.0, repeats n, first stride s).
_MOBILENET_V2_STAGES: tuple[tuple[int, int, int, int], ...] = (
    (1, 16, 1, 1),
    (6, 24, 2, 2),  # -> output stride 4: the low-level features for the decoder
    (6, 32, 3, 2),
    (6, 64, 4, 2),
    (6, 96, 3, 1),
    (6, 160, 3, 2),
    (6, 320, 1, 1),
)
_LOW_LEVEL_STAGE = 1


def _make_divisible(value: float, divisor: int = 8) -> int:
    """Round a channel count to a multiple of ``divisor`` without dropping below 90 %."""
    rounded = max(divisor, int(value + divisor / 2) // divisor * divisor)
    return rounded + divisor if rounded < 0.9 * value else rounded


class _ConvBNReLU(nn.Sequential):
    def __init__(
        self, c_in: int, c_out: int, k: int = 3, stride: int = 1, dilation: int = 1, groups: int = 1
    ) -> None:
        pad = dilation * (k - 1) // 2
        super().__init__(
            nn.Conv2d(c_in, c_out, k, stride, pad, dilation=dilation, groups=groups, bias=False),
            nn.BatchNorm2d(c_out),
            nn.ReLU6(inplace=True),
        )


class _SeparableConv(nn.Sequential):
    """Depthwise 3x3 (atrous) conv + BN + ReLU, then pointwise 1x1 conv + BN + ReLU."""

    def __init__(self, c_in: int, c_out: int, dilation: int = 1) -> None:
        super().__init__(
            _ConvBNReLU(c_in, c_in, 3, dilation=dilation, groups=c_in),
            _ConvBNReLU(c_in, c_out, 1),
        )


class _InvertedResidual(nn.Module):
    def __init__(self, c_in: int, c_out: int, stride: int, expansion: int, dilation: int) -> None:
        super().__init__()
        hidden = c_in * expansion
        layers: list[nn.Module] = []
        if expansion != 1:
            layers.append(_ConvBNReLU(c_in, hidden, 1))
        layers += [
            _ConvBNReLU(hidden, hidden, 3, stride, dilation, groups=hidden),
            nn.Conv2d(hidden, c_out, 1, bias=False),
            nn.BatchNorm2d(c_out),
        ]
        self.block = nn.Sequential(*layers)
        self.residual = stride == 1 and c_in == c_out

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return x + self.block(x) if self.residual else self.block(x)


class _Encoder(nn.Module):
    """MobileNetV2 features (no classifier) with atrous stages past ``output_stride``."""

    def __init__(self, in_channels: int, width: float, output_stride: int) -> None:
        super().__init__()
        c = _make_divisible(32 * width)
        self.stem = _ConvBNReLU(in_channels, c, 3, stride=2)
        stride_so_far, dilation = 2, 1
        stages: list[nn.Sequential] = []
        for t, channels, n, s in _MOBILENET_V2_STAGES:
            c_out = _make_divisible(channels * width)
            if s > 1 and stride_so_far >= output_stride:
                first_dilation, dilation, s = dilation, dilation * s, 1
            else:
                first_dilation = dilation
                stride_so_far *= s
            blocks = [_InvertedResidual(c, c_out, s, t, first_dilation)]
            blocks += [_InvertedResidual(c_out, c_out, 1, t, dilation) for _ in range(n - 1)]
            stages.append(nn.Sequential(*blocks))
            c = c_out
        self.stages = nn.ModuleList(stages)
        self.low_level_channels = _make_divisible(_MOBILENET_V2_STAGES[_LOW_LEVEL_STAGE][1] * width)
        self.out_channels = c

    def forward(self, x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        x = self.stem(x)
        low = x
        for i, stage in enumerate(self.stages):
            x = stage(x)
            if i == _LOW_LEVEL_STAGE:
                low = x
        return low, x


class _ASPP(nn.Module):
    """Atrous spatial pyramid pooling: 1x1, three atrous separable 3x3, image pooling."""

    def __init__(self, c_in: int, c_out: int, rates: tuple[int, int, int]) -> None:
        super().__init__()
        self.branches = nn.ModuleList(
            [_ConvBNReLU(c_in, c_out, 1)] + [_SeparableConv(c_in, c_out, r) for r in rates]
        )
        self.pool = nn.Sequential(
            nn.AdaptiveAvgPool2d(1), nn.Conv2d(c_in, c_out, 1, bias=False), nn.ReLU(inplace=True)
        )
        self.project = nn.Sequential(
            _ConvBNReLU(c_out * (len(rates) + 2), c_out, 1), nn.Dropout(0.1)
        )

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        pooled = self.pool(x).expand(-1, -1, x.shape[2], x.shape[3])
        return self.project(torch.cat([b(x) for b in self.branches] + [pooled], dim=1))


class DeepLabV3Plus(nn.Module):
    """DeepLabV3+ (Chen et al., ECCV 2018) with a MobileNetV2 encoder, for floor-plan drawings.

    Input: (N, in_channels, H, W) float, ink = 1, paper = 0 (see ``inference.to_tensor``); any
    H, W (multiples of 16 are cheapest). Output: (N, num_classes, H, W) logits at input size.

    Args:
        num_classes: output classes (10: the ``f2n_drake.core.classes`` label ids).
        output_stride: encoder stride at the ASPP, 16 (rates 6/12/18) or 8 (rates 12/24/36).
        width: MobileNetV2 width multiplier in (0, 2]; 0.5 gives ~0.7 M encoder parameters.
        in_channels: image channels, 1 for grey drawings.
        aspp_channels: channels of every ASPP branch and of its projection.
        decoder_channels: channels of the two 3x3 decoder convolutions.
        low_level_channels: channels the 1/4-resolution features are reduced to (48 in the paper).

    Raises:
        ValueError: an argument is out of range.
    """

    def __init__(
        self,
        num_classes: int = 10,
        output_stride: Literal[8, 16] = 16,
        width: float = 0.5,
        in_channels: int = 1,
        aspp_channels: int = 128,
        decoder_channels: int = 96,
        low_level_channels: int = 48,
    ) -> None:
        super().__init__()
        if output_stride not in (8, 16):
            raise ValueError(f"output_stride must be 8 or 16, got {output_stride!r}")
        if not (isinstance(num_classes, int) and num_classes >= 2):
            raise ValueError(f"num_classes must be an int >= 2, got {num_classes!r}")
        if not 0 < width <= 2:
            raise ValueError(f"width must be in (0, 2], got {width!r}")
        for name, value in (
            ("in_channels", in_channels),
            ("aspp_channels", aspp_channels),
            ("decoder_channels", decoder_channels),
            ("low_level_channels", low_level_channels),
        ):
            if not (isinstance(value, int) and value >= 1):
                raise ValueError(f"{name} must be a positive int, got {value!r}")
        self.config = dict(
            num_classes=num_classes,
            output_stride=output_stride,
            width=width,
            in_channels=in_channels,
            aspp_channels=aspp_channels,
            decoder_channels=decoder_channels,
            low_level_channels=low_level_channels,
        )
        rates = (6, 12, 18) if output_stride == 16 else (12, 24, 36)
        self.encoder = _Encoder(in_channels, width, output_stride)
        self.aspp = _ASPP(self.encoder.out_channels, aspp_channels, rates)
        self.reduce = _ConvBNReLU(self.encoder.low_level_channels, low_level_channels, 1)
        self.decoder = nn.Sequential(
            _SeparableConv(aspp_channels + low_level_channels, decoder_channels),
            _SeparableConv(decoder_channels, decoder_channels),
        )
        self.classifier = nn.Conv2d(decoder_channels, num_classes, 1)
        self._init_weights()

    def _init_weights(self) -> None:
        for m in self.modules():
            if isinstance(m, nn.Conv2d):
                nn.init.kaiming_normal_(m.weight, mode="fan_out")
                if m.bias is not None:
                    nn.init.zeros_(m.bias)
            elif isinstance(m, nn.BatchNorm2d):
                nn.init.ones_(m.weight)
                nn.init.zeros_(m.bias)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        size = x.shape[-2:]
        low, high = self.encoder(x)
        high = self.aspp(high)
        high = F.interpolate(high, size=low.shape[-2:], mode="bilinear", align_corners=False)
        x = self.decoder(torch.cat([high, self.reduce(low)], dim=1))
        return F.interpolate(self.classifier(x), size=size, mode="bilinear", align_corners=False)


def count_parameters(model: nn.Module) -> int:
    """Number of trainable parameters."""
    return sum(p.numel() for p in model.parameters() if p.requires_grad)


def fold_batch_norms(model: nn.Module) -> nn.Module:
    """An inference copy of ``model``: each BatchNorm2d that follows a Conv2d folded into it.

    An eval-mode batch norm is an affine map per channel, so it becomes the convolution's
    weight scale and bias, and one pass over the activations less (about 15 % of a CPU forward
    pass of this network; same logits to float rounding). The copy is in eval mode and is
    for inference only: its batch norms are gone. ``model`` itself is unchanged.
    """
    folded = copy.deepcopy(model).eval()
    for seq in folded.modules():
        if not isinstance(seq, nn.Sequential):
            continue
        for i in range(len(seq) - 1):
            conv, norm = seq[i], seq[i + 1]
            if isinstance(conv, nn.Conv2d) and isinstance(norm, nn.BatchNorm2d):
                seq[i] = fuse_conv_bn_eval(conv, norm)
                seq[i + 1] = nn.Identity()
    return folded
