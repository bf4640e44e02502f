"""Decks: the Jinja template environment, rendering of case directories, STL meshes, the
LIGGGHTS material block and the physical checks of a case before it is run.
"""
