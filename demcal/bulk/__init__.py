"""Bulk values: one case's bulk values from its run, the tidy dataset of a study, the run
times of its DEM cases, and synthetic measurements made by running cases at known parameters.
"""
