"""Shared core: configuration and its schema validation, parameter names and physical
constants, measured data, steady-state detection of time series, provenance sidecars and rule
logging. Every stage imports from here; this package imports from no stage.
"""
