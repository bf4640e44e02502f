"""Surrogates: neural networks per bulk value, the baselines, regression metrics (Table 4),
training and figures.
"""
