"""The paper's two CNNs (Sharma et al. 2021, supplementary §2), exactly.

Input layout is NCHW = (batch, colour channel, space, time) = (N, 3, 64, 256): the
space-time plot with channels first, as produced by
``wallcli.signal.window.normalize_window``.  ``forward`` returns raw scores (logits)
because ``nn.CrossEntropyLoss`` applies log-softmax itself; ``WithSoftmax`` wraps a net
for export so the shipped ONNX model outputs probabilities, as the seed's nets do.
"""
from __future__ import annotations

import torch
from torch import nn

CHANNELS = 3
BINS = 64
WINDOW = 256
FEATURES = 64
SLOPE = 0.1

COUNT_CLASSES = [0, 1, 2]
ACTIVITY_CLASSES = ["none", "walking", "crouching", "waving", "jumping"]


def _block(c_in: int, kernel: int, padding: int, pool: bool) -> list[nn.Module]:
    # bias is redundant before batch norm (BN's shift replaces it)
    layers: list[nn.Module] = [
        nn.Conv2d(c_in, FEATURES, kernel, stride=1, padding=padding, bias=False),
        nn.BatchNorm2d(FEATURES),
        nn.LeakyReLU(SLOPE),
    ]
    if pool:
        layers.append(nn.MaxPool2d(2))
    return layers


class Trunk(nn.Module):
    """Blocks 1-5 plus the max over time: (N, 3, 64, 256) -> (N, 64)."""

    def __init__(self) -> None:
        super().__init__()
        layers: list[nn.Module] = []
        for i in range(4):  # 5x5, zero padding 2 keeps size; pool halves: 64x256 -> 4x16
            layers += _block(CHANNELS if i == 0 else FEATURES, 5, 2, pool=True)
        layers += _block(FEATURES, 4, 0, pool=False)  # 4x4 valid: 4x16 -> 1x13
        self.blocks = nn.Sequential(*layers)

    def feature_map(self, x: torch.Tensor) -> torch.Tensor:
        return self.blocks(x)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        f = self.blocks(x)  # (N, 64, 1, 13)
        return torch.amax(f, dim=(2, 3))


class CountNet(nn.Module):
    """Counting net: horizontal plot -> scores for 0, 1, 2 people."""

    task = "count"
    classes = COUNT_CLASSES
    input_names = ("horizontal",)

    def __init__(self) -> None:
        super().__init__()
        self.trunk = Trunk()
        self.head = nn.Sequential(
            nn.Linear(FEATURES, FEATURES), nn.LeakyReLU(SLOPE), nn.Linear(FEATURES, len(COUNT_CLASSES))
        )

    def forward(self, horizontal: torch.Tensor) -> torch.Tensor:
        return self.head(self.trunk(horizontal))


class ActivityNet(nn.Module):
    """Activity net: one trunk per plot, features concatenated -> 5 scores."""

    task = "activity"
    classes = ACTIVITY_CLASSES
    input_names = ("horizontal", "vertical")

    def __init__(self) -> None:
        super().__init__()
        self.trunk_h = Trunk()
        self.trunk_v = Trunk()
        self.head = nn.Sequential(
            nn.Linear(2 * FEATURES, 64), nn.LeakyReLU(SLOPE),
            nn.Linear(64, 32), nn.LeakyReLU(SLOPE),
            nn.Linear(32, len(ACTIVITY_CLASSES)),
        )

    def forward(self, horizontal: torch.Tensor, vertical: torch.Tensor) -> torch.Tensor:
        f = torch.cat([self.trunk_h(horizontal), self.trunk_v(vertical)], dim=1)
        return self.head(f)


LITE_FEATURES = 32


class LiteTrunk(nn.Module):
    """A trunk for the 'lite' nets: time averaged in pairs (15 samples/s keep 0-7.5 Hz, above any
    gait, wave or jump), then the seed's five blocks at 32 channels: about an eighth of the seed
    trunk's work, so a net reading both plots costs less than the seed's count net.
    (N, 3, 64, 256) -> (N, 32)."""

    def __init__(self) -> None:
        super().__init__()
        layers: list[nn.Module] = [nn.AvgPool2d((1, 2))]
        for i in range(4):
            layers += [nn.Conv2d(CHANNELS if i == 0 else LITE_FEATURES, LITE_FEATURES, 5, padding=2, bias=False),
                       nn.BatchNorm2d(LITE_FEATURES), nn.LeakyReLU(SLOPE), nn.MaxPool2d(2)]
        layers += [nn.Conv2d(LITE_FEATURES, LITE_FEATURES, 4, bias=False), nn.BatchNorm2d(LITE_FEATURES), nn.LeakyReLU(SLOPE)]
        self.blocks = nn.Sequential(*layers)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return torch.amax(self.blocks(x), dim=(2, 3))


class LiteNet(nn.Module):
    """Both plots for either task (arch 'lite'): a whole-wall change of light is removed by
    normalisation v3, so a jump or a crouch that shows mostly in the vertical plot must be read
    there, by count too."""

    input_names = ("horizontal", "vertical")

    def __init__(self, task: str) -> None:
        super().__init__()
        self.task = task
        self.classes = COUNT_CLASSES if task == "count" else ACTIVITY_CLASSES
        self.trunk_h = LiteTrunk()
        self.trunk_v = LiteTrunk()
        self.head = nn.Sequential(nn.Linear(2 * LITE_FEATURES, 64), nn.LeakyReLU(SLOPE), nn.Dropout(0.2),
                                  nn.Linear(64, len(self.classes)))

    def forward(self, horizontal: torch.Tensor, vertical: torch.Tensor) -> torch.Tensor:
        return self.head(torch.cat([self.trunk_h(horizontal), self.trunk_v(vertical)], dim=1))


ARCHS = ("seed", "lite")


class WithSoftmax(nn.Module):
    """Export wrapper: probabilities instead of scores (the seed ends both nets in softmax)."""

    def __init__(self, net: nn.Module) -> None:
        super().__init__()
        self.net = net

    def forward(self, *inputs: torch.Tensor) -> torch.Tensor:
        return torch.softmax(self.net(*inputs), dim=1)


def build(task: str, arch: str = "seed") -> nn.Module:
    if arch == "lite":
        if task not in ("count", "activity"):
            raise ValueError(f"unknown task {task!r}")
        return LiteNet(task)
    if arch != "seed":
        raise ValueError(f"unknown architecture {arch!r}")
    if task == "count":
        return CountNet()
    if task == "activity":
        return ActivityNet()
    raise ValueError(f"unknown task {task!r}")
