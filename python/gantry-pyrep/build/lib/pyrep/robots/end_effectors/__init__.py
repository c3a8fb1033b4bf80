"""PyRep's end effectors: grippers and suction cups."""
