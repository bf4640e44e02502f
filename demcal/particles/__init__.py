"""Particles: size distributions, the material set-up and the time step that every virtual
test and the application share.
"""
