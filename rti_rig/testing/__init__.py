"""Test harnesses (not used by the product): kill a session at a chosen step, check its images.

Used by the test suite and ``benchmarks/fault_campaign.py``; nothing in ``rti_rig`` imports it.
"""
