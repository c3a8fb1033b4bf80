"""The layer between PyRep's classes and the simulator: `sim` (CoppeliaSim 4.1's C
names over gantry), `session` (which simulation a thread talks to) and `utils`."""
