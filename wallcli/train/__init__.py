"""Training (the optional extra ``train``, see wallcli/extras.py: torch is imported only inside this package).

- ``nets``: the seed's counting and two-branch activity CNNs, input (N, 3, 64, 256).
- ``data``: the simulator's shard datasets, planned per epoch so resume is exact.
- ``augment``: label-preserving augmentation applied to raw windows before normalisation.
- ``loop``: RMSProp 1e-3 + cross-entropy, checkpoints, validation, best-epoch selection.
- ``export``: ONNX (opset 17, dynamic batch, softmax output), parity check, model card.

Shipped models are reproduced with (see each card's ``training.command``)::

    wallcli simulate --dataset N --task count -o data/count --seed S --jobs 2
    wallcli simulate --dataset M --task count --domain shifted -o data/val_count --seed S2
    wallcli train count --data data/count --val data/val_count --out models/count.onnx
"""
