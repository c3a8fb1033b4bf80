"""PyRep's mobile bases."""
