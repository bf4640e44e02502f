"""Design of DEM cases: the parameter design table and its expansion into one case per run."""
