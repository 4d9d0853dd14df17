"""Allow `python -m rti_rig`."""

from rti_rig.launch import main

main()
