"""Paths in a robot's configuration space, and how robots follow them."""
