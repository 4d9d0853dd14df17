"""Use cases: one module per thing a user does, taking a request and returning a result."""
