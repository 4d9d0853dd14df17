"""The light planner: preview → relief → normals → an ordered light schedule.

Installed as ``rti_rig.planner``; built on ``rti_rig.core`` only.
"""
