"""Dataset mode: simulated scenes through the real video -> stplot path, cut into labelled windows.

May import wallcli.io and wallcli.signal (unlike wallcli.sim), because windows must come out of
exactly the code that reads real videos.
"""
