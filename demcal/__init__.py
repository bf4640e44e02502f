"""demcal: calibration of DEM contact parameters from bulk experiments."""

__version__ = "0.1.0"
