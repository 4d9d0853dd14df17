"""Use cases: one function per thing a user asks for, taking a request and returning a result."""
