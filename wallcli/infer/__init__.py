"""Inference at run time, onnxruntime only (no torch).

- ``card``: the model card format (read, validate, sha256).
- ``model``: a model + card, sha256-checked, lazily created onnxruntime session.
- ``stream``: a video decoded once into resampled space-time rows.
- ``windows``: rows cut into windows, corrected, through the nets; ``judge``: may an answer be
  relied upon; ``result``: the docs/contract.md objects.
- ``classify``: wires those stages for a space-time plot, a file or a live stream.
"""
