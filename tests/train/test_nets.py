import pytest

torch = pytest.importorskip("torch")
from torch import nn  # noqa: E402

from wallcli.train.nets import ActivityNet, CountNet, Trunk, WithSoftmax, build  # noqa: E402


def test_trunk_block5_ends_at_space_1_time_13():
    trunk = Trunk().eval()
    x = torch.randn(2, 3, 64, 256)
    assert trunk.feature_map(x).shape == (2, 64, 1, 13)
    assert trunk(x).shape == (2, 64)


def test_trunk_layers_are_the_seeds():
    convs = [m for m in Trunk().modules() if isinstance(m, nn.Conv2d)]
    assert [c.kernel_size for c in convs] == [(5, 5)] * 4 + [(4, 4)]
    assert [c.padding for c in convs] == [(2, 2)] * 4 + [(0, 0)]
    assert all(c.stride == (1, 1) and c.out_channels == 64 for c in convs)
    assert convs[0].in_channels == 3
    mods = list(Trunk().blocks)
    assert sum(isinstance(m, nn.BatchNorm2d) for m in mods) == 5
    assert sum(isinstance(m, nn.MaxPool2d) for m in mods) == 4
    assert all(m.negative_slope == 0.1 for m in mods if isinstance(m, nn.LeakyReLU))


def test_count_net_output_and_head():
    net = CountNet().eval()
    assert net(torch.randn(3, 3, 64, 256)).shape == (3, 3)
    lin = [m for m in net.head if isinstance(m, nn.Linear)]
    assert [(m.in_features, m.out_features) for m in lin] == [(64, 64), (64, 3)]


def test_activity_net_two_branches_and_head():
    net = ActivityNet().eval()
    h, v = torch.randn(2, 3, 64, 256), torch.randn(2, 3, 64, 256)
    assert net(h, v).shape == (2, 5)
    lin = [m for m in net.head if isinstance(m, nn.Linear)]
    assert [(m.in_features, m.out_features) for m in lin] == [(128, 64), (64, 32), (32, 5)]
    # the branches are separate: the vertical plot changes the answer through its own trunk only
    assert net.trunk_h is not net.trunk_v
    out_a = net(h, v)
    out_b = net(h, torch.randn(2, 3, 64, 256))
    assert not torch.allclose(out_a, out_b)


def test_softmax_wrapper_sums_to_one():
    p = WithSoftmax(build("count")).eval()(torch.randn(4, 3, 64, 256))
    assert torch.allclose(p.sum(1), torch.ones(4), atol=1e-6)


def test_build_unknown_task():
    with pytest.raises(ValueError):
        build("dance")
