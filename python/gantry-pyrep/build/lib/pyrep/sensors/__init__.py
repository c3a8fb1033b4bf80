"""PyRep's composite sensors: accelerometer, gyroscope, spherical vision sensor."""
