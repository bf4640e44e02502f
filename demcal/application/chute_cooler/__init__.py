"""Sinter chute-cooler segregation (paper Figs. 10-11): set-up, deck, analysis and figures.
"""
