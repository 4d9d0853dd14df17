"""Device drivers: LED domes (pyserial), Dynamixel arms (dynamixel-sdk), cameras.

Installed as ``rti_rig.drivers``; built on ``rti_rig.core`` only.
"""
