"""Use cases: one module per thing a user asks of rti-rig, each taking a request dataclass."""
