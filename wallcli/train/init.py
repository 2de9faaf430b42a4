"""Start training from an exported model (``wallcli train --init MODEL.onnx``): fine-tuning.

An exported graph has no batch norm left: the exporter folds each block's BN into its
convolution (weight and bias), and an int8 graph stores those as quantised initialisers behind
DequantizeLinear. Loading it back gives each block's conv the folded weight, and its BN the
parameters that make it compute exactly "+ folded bias" in eval mode while its *train-mode*
output (batch statistics) starts close to that too: with the conv output's per-channel mean mu
and variance s^2 measured on real windows, BN gets running mean mu, running variance s^2,
weight sqrt(s^2 + eps) and bias (folded bias + mu). Without that, the first training step
would normalise with batch statistics the folded weights were never meant for.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from wallcli.errors import WallcliError
from wallcli.train.quantize import dequantize


def _initializers(model) -> dict[str, np.ndarray]:
    from onnx import numpy_helper

    return {i.name: numpy_helper.to_array(i) for i in model.graph.initializer}


def _value(name: str, init: dict[str, np.ndarray], made_by: dict[str, Any]) -> np.ndarray:
    """A constant input as float64: an initializer, or a DequantizeLinear of initializers."""
    if name in init:
        return init[name].astype(np.float64)
    node = made_by.get(name)
    if node is None or node.op_type != "DequantizeLinear" or any(i and i not in init for i in node.input):
        raise WallcliError(f"weight {name!r} is neither a constant nor a dequantised constant")
    return dequantize(node, init)[0]


def _module(net: nn.Module, node_name: str) -> tuple[nn.Module, nn.Module | None]:
    """'/net/trunk_h/blocks/blocks.4/Conv' -> (net.trunk_h.blocks[4], the BN after it, [5]);
    '/net/head/head.2/Gemm' -> (net.head[2], None). Names are the exporter's scopes."""
    parts = node_name.strip("/").split("/")[1:-1]  # drop the 'net' wrapper and the op
    parent, index = ".".join(parts[:-1]), parts[-1].rsplit(".", 1)[-1]
    mod = net.get_submodule(f"{parent}.{index}")
    bn = net.get_submodule(f"{parent}.{int(index) + 1}") if isinstance(mod, nn.Conv2d) else None
    return mod, bn


def init_from_onnx(net: nn.Module, path: Path | str, calib: list[torch.Tensor]) -> None:
    """Load ``path``'s weights into ``net`` (the same architecture); ``calib``: one batch of
    normalised inputs (N, 3, bins, window) per net input, to set the BN statistics."""
    import onnx

    path = Path(path)
    try:
        model = onnx.load(str(path))
    except Exception as e:
        raise WallcliError(f"cannot read {path} as an ONNX model: {str(e).splitlines()[0]}") from None
    if any(n.op_type == "BatchNormalization" for n in model.graph.node):
        raise WallcliError(f"{path} has unfolded batch norms; --init reads graphs written by 'wallcli train'")
    init = _initializers(model)
    made_by = {o: n for n in model.graph.node for o in n.output}
    convs: list[tuple[nn.Conv2d, nn.BatchNorm2d, np.ndarray]] = []
    linears = 0
    try:
        with torch.no_grad():
            for node in model.graph.node:
                if node.op_type == "Conv":
                    conv, bn = _module(net, node.name)
                    w = _value(node.input[1], init, made_by)
                    b = _value(node.input[2], init, made_by) if len(node.input) > 2 else np.zeros(w.shape[0])
                    if not isinstance(bn, nn.BatchNorm2d) or tuple(conv.weight.shape) != w.shape:
                        raise WallcliError(f"{path}: {node.name} does not match this net ({tuple(w.shape)})")
                    conv.weight.copy_(torch.from_numpy(w))
                    bn.weight.fill_(1.0)
                    bn.bias.copy_(torch.from_numpy(b))
                    bn.running_mean.zero_()
                    bn.running_var.fill_(1.0 - bn.eps)  # eval: x / sqrt(var + eps) = x
                    convs.append((conv, bn, b))
                elif node.op_type == "Gemm":
                    lin, _ = _module(net, node.name)
                    w = _value(node.input[1], init, made_by)
                    if not next((a.i for a in node.attribute if a.name == "transB"), 0):
                        w = w.T
                    if not isinstance(lin, nn.Linear) or tuple(lin.weight.shape) != w.shape:
                        raise WallcliError(f"{path}: {node.name} does not match this net ({tuple(w.shape)})")
                    lin.weight.copy_(torch.from_numpy(w))
                    lin.bias.copy_(torch.from_numpy(_value(node.input[2], init, made_by)))
                    linears += 1
    except (AttributeError, IndexError, ValueError, TypeError) as e:
        raise WallcliError(f"{path} is not a {getattr(net, 'task', '')} model written by 'wallcli train' ({e})") from None
    n_conv = sum(isinstance(m, nn.Conv2d) for m in net.modules())
    n_lin = sum(isinstance(m, nn.Linear) for m in net.modules())
    if len(convs) != n_conv or linears != n_lin:
        raise WallcliError(f"{path} has {len(convs)} convolutions and {linears} linear layers; "
                           f"this net has {n_conv} and {n_lin}")

    # the conv outputs' statistics on real windows, with the graph's function (eval mode)
    stats: dict[nn.Module, tuple[torch.Tensor, torch.Tensor]] = {}

    def hook(mod, _inp, out):
        stats[mod] = (out.mean(dim=(0, 2, 3)), out.var(dim=(0, 2, 3), unbiased=False))

    handles = [c.register_forward_hook(hook) for c, _, _ in convs]
    was_training = net.training
    net.eval()
    try:
        with torch.no_grad():
            net(*calib)
    finally:
        for h in handles:
            h.remove()
        net.train(was_training)
    with torch.no_grad():
        for conv, bn, b in convs:
            mu, var = (s.double() for s in stats[conv])
            var = var.clamp_min(1e-12)
            bn.running_mean.copy_(mu)
            bn.running_var.copy_(var)
            bn.weight.copy_(torch.sqrt(var + bn.eps))
            bn.bias.copy_(torch.from_numpy(b) + mu)
