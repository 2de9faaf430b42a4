"""wallcli: what you can learn by staring at a blank wall.

The package is a pipeline: ``io`` (bytes <-> arrays) -> ``signal`` (the method, pure numpy)
-> ``plots`` / ``infer`` / ``sim`` -> ``cli``. Nothing below ``cli`` prints.
"""

__version__ = "0.1.0"
