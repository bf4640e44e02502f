"""Bulk values: one case's bulk values from its run, the tidy dataset of a study, and
synthetic measurements made by running cases at known parameters.
"""
