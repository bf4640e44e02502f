"""Sinter chute-cooler segregation (paper Figs. 10-11): contact parameters, set-up and its
layout record, meshes, deck, analysis and figures.
"""
