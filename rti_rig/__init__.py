"""rti_rig package."""
