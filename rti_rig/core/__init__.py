"""The core: the vocabulary every other layer speaks, importing nothing else of rti-rig.

Frame and geometry (``geometry``, ``rig_geometry``), the light schedule, the ``.lp`` format,
the device capability protocols (``devices``), the dome link protocol (``dome_link``), the
relighting bases, the clock and the errors. See ``docs/conventions.md`` for the frame and the
``.lp`` profile, and ``docs/architecture.md`` for the layers.
"""
