"""Camera drivers: UVC via OpenCV, DSLRs via python-gphoto2, watched folders, RAW decoding.

All of them implement :class:`rti_rig.core.devices.Camera` and return linear
:class:`rti_rig.core.devices.Frame` data. See docs/cameras.md.
"""
