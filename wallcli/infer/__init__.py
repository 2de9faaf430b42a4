"""Inference at run time, onnxruntime only (no torch).

- ``card``: the model card format (read, validate, sha256).
- ``model``: a model + card, sha256-checked, lazily created onnxruntime session.
- ``classify``: sliding windows over a space-time plot or a live stream; docs/contract.md results.
"""
