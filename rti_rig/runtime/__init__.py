"""The runtime: executing a schedule on a rig (controller, lighting, device policies, session
store).

Built on the core only; it never sees a driver, a config file or the CLI. The composition root
(``rti_rig.app.compose``) hands it a :class:`rti_rig.runtime.rig.Rig` made of devices that
implement the core's capability protocols.
"""
