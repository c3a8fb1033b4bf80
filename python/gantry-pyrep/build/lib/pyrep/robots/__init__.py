"""PyRep's robots: arms, end effectors (grippers, suction cups), mobile bases and the
configuration-space paths that move them, found in the scene by their parts' names."""
