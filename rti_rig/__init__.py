"""rti-rig: controller for Reflectance Transformation Imaging rigs."""

__version__ = "0.1.0"
