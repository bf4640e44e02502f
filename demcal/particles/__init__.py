"""Particles: size distributions, the material set-up and the time step, and the run set-up
(simulation box, output intervals, insertion seeds) that every virtual test and the application
share.
"""
