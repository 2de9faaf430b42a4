"""Validate a model on labelled recordings: ``wallcli evaluate DIR --task count|activity``.

labels.py reads the labels, clip.py analyses one clip (one decode: the classifier's answer and
the measured SNR), pool.py runs clips in worker processes where a crash is one clip's error,
score.py turns rows into figures, run.py puts them together as CONTRACT.md lays out.
"""
from wallcli.evaluate.run import evaluate_folder

__all__ = ["evaluate_folder"]
