"""PyRep's arms, one module each."""
