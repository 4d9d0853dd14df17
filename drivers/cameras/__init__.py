"""Camera drivers: UVC via OpenCV, DSLRs via python-gphoto2, watched folders, RAW decoding.

All of them implement :class:`rti_rig.rig.Camera` and return linear :class:`rti_rig.rig.Frame`
data. See docs/cameras.md.
"""
