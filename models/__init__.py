"""Shipped ONNX models and their model cards (installed as the package ``wallcli.models``)."""
