"""Rig configs shipped with rti-rig (TOML), importable so installed copies can find them."""
