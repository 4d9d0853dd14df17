"""Allow `python -m rti_rig`."""

from rti_rig.cli import main

main()
