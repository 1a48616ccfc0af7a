"""Calibration of particle-scale DEM parameters against Jenike shear tests."""
