"""The simulated rig: a renderer of believable surfaces and device emulators that speak real bytes.

Installed as ``rti_rig.simulator``; built on ``rti_rig.core`` (and the drivers' pure codecs).
"""
