"""Virtual lifted-cylinder angle of repose: set-up and the slice / convex-hull readout."""
