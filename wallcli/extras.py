"""How to install an optional extra, said the one way that works: wallcli is not on the package
index, so ``pip install 'wallcli[train]'`` fails; the extra's own packages install from anywhere,
and ``'.[train]'`` from the top folder of a checkout (as the README installs). Hints go inside
an error's parentheses: no parentheses of their own."""

_CHECKOUT = "; or, from the top folder of the wallcli checkout, "
TRAIN = "pip install torch==2.13.0 'onnx>=1.15'" + _CHECKOUT + "pip install torch==2.13.0 && pip install '.[train]'"
ONNX = "pip install 'onnx>=1.15'" + _CHECKOUT + "pip install '.[train]'"
PT = "pip install mitsuba==3.9.1" + _CHECKOUT + "pip install '.[pt]'"
